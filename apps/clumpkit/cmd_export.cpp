// clumpkit export CLUMP.json --format FMT -o DIR: a clump template to a DEM code's files.
#include <fmt/format.h>

#include <iostream>

#include "cli_util.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/export/exporter.hpp"
#include "clumpkit/geometry/clump_template.hpp"

namespace clumpkit::cli {
namespace {

struct ExportArgs {
  std::string clump, format, out, name, json;
  int type = 1, atom_type = 1;
};

std::string formats_help() {
  std::string h = "Target format:";
  for (const Exporter& e : exporters()) h += fmt::format("\n  {:<11} {}", e.name, e.description);
  return h;
}

Command setup_export(CLI::App& parent) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* c = parent.add_subcommand(
      "export",
      "Export a clump template to a DEM code. Everything is written in the clump's "
      "centroid-principal frame (metres, SI), with the rotation and translation back to the "
      "source shape and the sphere union's mass, volume, density and principal moments. "
      "-o is always an output FOLDER (created if missing; its parent must exist); the files in "
      "it are named after --name (BASE, default: the template's name). All files are written "
      "or none: nothing is left behind on error.");
  c->add_option("CLUMP", args->clump, "Clump template (.json, clumpkit-clump/1)")->required();
  c->add_option("--format", args->format, formats_help())->required();
  c->add_option("-o,--output", args->out, "Output folder")->required();
  c->add_option("--name", args->name, "Base name of the files (BASE); default: template name");
  c->add_option("--type", args->type, "LIGGGHTS multisphere template type (consecutive from 1)")
      ->check(CLI::PositiveNumber);
  c->add_option("--atom-type", args->atom_type, "Atom type of the spheres (LIGGGHTS, LAMMPS)")
      ->check(CLI::PositiveNumber);
  c->add_option("--json", args->json, "Also write what was written as JSON (FILE or -)");
  return {c, [args] {
            if (!find_exporter(args->format))
              throw InputError(
                  "", "--format",
                  fmt::format("unknown format '{}' (known: {})", args->format, exporter_names()));
            const ClumpTemplate t = load_clump(args->clump);
            ExportSettings s;
            s.base_name = args->name;
            s.template_type = args->type;
            s.atom_type = args->atom_type;
            const auto written = export_clump(t, args->format, args->out, s);
            std::cout << fmt::format("exported {} ({} spheres, union mass {:.6g} kg) as {}:\n",
                                     t.name.empty() ? args->clump : t.name, t.spheres.size(),
                                     t.mass.mass, args->format);
            nlohmann::json files = nlohmann::json::array();
            for (const auto& p : written) {
              std::cout << "  " << p.string() << "\n";
              files.push_back(p.string());
            }
            if (!args->json.empty())
              write_json({{"format", args->format},
                          {"folder", args->out},
                          {"files", files},
                          {"spheres", t.spheres.size()},
                          {"mass_kg", t.mass.mass},
                          {"volume_m3", t.mass.volume},
                          {"density_kg_m3", t.mass.density}},
                         args->json);
            return 0;
          }};
}

const Registration reg_export(30, setup_export);

}  // namespace
}  // namespace clumpkit::cli
