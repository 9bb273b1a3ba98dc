// clumpkit paper: the paper's nine clump models (pills A, B, C), filled and tabulated.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <optional>

#include "cli_util.hpp"
#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/fill/paper_fill.hpp"
#include "clumpkit/geometry/mass_properties.hpp"
#include "clumpkit/geometry/shape_spec.hpp"

namespace clumpkit::cli {
namespace {

struct PaperArgs {
  std::string out, json;
  std::int64_t rays = RaySamplingOptions{}.rays;
};

Command setup_paper(CLI::App& parent) {
  auto args = std::make_shared<PaperArgs>();
  CLI::App* c = parent.add_subcommand(
      "paper",
      "The paper's nine clump models: fill pills A, B, C (A/B 4, 12, 20; C 2, 12, 18 "
      "spheres) and print sphere counts and union mass properties");
  c->add_option("--out", args->out, "Also write the nine templates to this folder");
  c->add_option("--json", args->json, "Write the table as JSON (FILE or -)");
  c->add_option("--rays", args->rays, "Rays per mass-property integration")
      ->check(CLI::PositiveNumber);
  return {c, [args] {
            namespace fs = std::filesystem;
            if (!args->json.empty() && args->json != "-") check_writable(args->json, "--json");
            std::optional<OutputFolder> out_folder;  // gone again if nothing is written
            if (!args->out.empty()) out_folder.emplace(args->out, "--out");
            nlohmann::json rows = nlohmann::json::array();
            std::cout << fmt::format(
                "{:<6} {:>7} {:>8} {:>10} {:>10} {:>9} {:>9} {:>9} {:>9} {:>9}\n", "model",
                "spheres", "r (mm)", "V (mm^3)", "V/Vcyl", "m (g)", "I1", "I2", "I3", "Icyl3");
            std::cout << fmt::format("{:<6} {:>7} {:>8} {:>10} {:>10} {:>9} {:>29} {:>9}\n", "", "",
                                     "", "union", "", "union", "principal, g mm^2", "");
            for (const PaperModel& pm : paper_models()) {
              const ShapeSpec shape = load_shape(resolve_shape(std::string("pill_") + pm.pill));
              PaperFillRequest req;
              req.spheres = pm.spheres;
              req.sampling.rays = args->rays;
              const ClumpTemplate t = paper_fill_template(shape, req);
              const MassProperties cyl =
                  cylinder_mass_properties(0.5 * shape.diameter, shape.height, shape.density);
              const auto& m = t.mass;
              std::cout << fmt::format(
                  "{:<6} {:>7} {:>8.4f} {:>10.3f} {:>10.4f} {:>9.4f} {:>9.4f} {:>9.4f} {:>9.4f} "
                  "{:>9.4f}\n",
                  fmt::format("{}{}", pm.pill, pm.spheres), t.spheres.size(),
                  t.spheres.front().radius * 1e3, m.volume * 1e9, m.volume / cyl.volume,
                  m.mass * 1e3, m.principal_moments[0] * 1e9, m.principal_moments[1] * 1e9,
                  m.principal_moments[2] * 1e9, cyl.principal_moments[2] * 1e9);
              rows.push_back(
                  {{"model", fmt::format("{}{}", pm.pill, pm.spheres)},
                   {"pill", std::string(1, pm.pill)},
                   {"spheres", t.spheres.size()},
                   {"sphere_radius_m", t.spheres.front().radius},
                   {"union_volume_m3", m.volume},
                   {"cylinder_volume_m3", cyl.volume},
                   {"union_mass_kg", m.mass},
                   {"principal_moments_kg_m2",
                    {m.principal_moments[0], m.principal_moments[1], m.principal_moments[2]}}});
              if (!args->out.empty()) save_clump(t, fs::path(args->out) / (t.name + ".json"));
            }
            std::cout << "V/Vcyl: union volume over the true cylinder's; masses at 1380 kg/m^3 on "
                         "the sphere-union basis.\n";
            if (!args->json.empty()) write_json({{"models", rows}}, args->json);
            return 0;
          }};
}

const Registration reg_paper(5, setup_paper);

}  // namespace
}  // namespace clumpkit::cli
