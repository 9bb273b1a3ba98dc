// clumpkit info CLUMP.json: a readable summary of a clump template.
#include <fmt/format.h>

#include <iostream>

#include "cli_util.hpp"
#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/geometry/clump_template.hpp"

namespace clumpkit::cli {
namespace {

struct InfoArgs {
  std::string clump, json;
};

Command setup_info(CLI::App& parent) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* c = parent.add_subcommand("info",
                                      "Summarise a clump template (spheres, mass "
                                      "properties, frame, provenance)");
  c->add_option("CLUMP", args->clump, "Clump template (.json)")->required();
  c->add_option("--json", args->json, "Also write the template's summary as JSON (FILE or -)");
  return {c, [args] {
            if (!args->json.empty() && args->json != "-") check_writable(args->json, "--json");
            const ClumpTemplate t = load_clump(args->clump);
            const MassProperties& m = t.mass;
            std::cout << fmt::format("clump      {}\n", t.name.empty() ? args->clump : t.name);
            // Provenance is free-form JSON: print non-strings as JSON rather than fail.
            const auto text = [](const nlohmann::json& j, const char* key) {
              const auto it = j.find(key);
              if (it == j.end()) return std::string();
              return it->is_string() ? it->get<std::string>() : it->dump();
            };
            if (t.source.contains("shape"))
              std::cout << fmt::format("source     {} ({})\n", text(t.source, "shape"),
                                       text(t.source, "kind"));
            if (t.method.contains("name"))
              std::cout << fmt::format("method     {}\n", t.method.dump());
            std::cout << fmt::format("spheres    {}\n", t.spheres.size());
            double rmin = 1e300, rmax = 0;
            for (const Sphere& s : t.spheres) {
              rmin = std::min(rmin, s.radius);
              rmax = std::max(rmax, s.radius);
            }
            std::cout << fmt::format("radii      {:.4f} .. {:.4f} mm\n", rmin * 1e3, rmax * 1e3);
            std::cout << fmt::format("basis      {}\n", t.mass_method.value("basis", "?"));
            std::cout << fmt::format("density    {:.6g} kg/m^3\n", m.density);
            std::cout << fmt::format("volume     {:.6g} mm^3 (+/- {:.2g}, 95 %)\n", m.volume * 1e9,
                                     t.mass_ci.volume * 1e9);
            std::cout << fmt::format("mass       {:.6g} g\n", m.mass * 1e3);
            std::cout << fmt::format("principal  {:.6g} {:.6g} {:.6g} g mm^2\n",
                                     m.principal_moments[0] * 1e9, m.principal_moments[1] * 1e9,
                                     m.principal_moments[2] * 1e9);
            std::cout << fmt::format("frame      translation [{:.6g} {:.6g} {:.6g}] mm\n",
                                     t.translation[0] * 1e3, t.translation[1] * 1e3,
                                     t.translation[2] * 1e3);
            for (int i = 0; i < 3; ++i)
              std::cout << fmt::format("           rotation    [{: .6f} {: .6f} {: .6f}]\n",
                                       t.rotation(i, 0), t.rotation(i, 1), t.rotation(i, 2));
            std::cout << "spheres (template frame, mm):\n";
            for (size_t i = 0; i < t.spheres.size(); ++i) {
              const Sphere& s = t.spheres[i];
              std::cout << fmt::format("  {:3d}  x {: .4f}  y {: .4f}  z {: .4f}  r {:.4f}\n", i,
                                       s.center[0] * 1e3, s.center[1] * 1e3, s.center[2] * 1e3,
                                       s.radius * 1e3);
            }
            if (!t.error.is_null()) std::cout << "error      " << t.error.dump() << "\n";
            if (!args->json.empty()) write_json(to_json(t), args->json);
            return 0;
          }};
}

const Registration reg_info(20, setup_info);

}  // namespace
}  // namespace clumpkit::cli
