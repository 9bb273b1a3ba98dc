// clumpkit fill SHAPE --method paper --spheres N -o OUT.json
#include <fmt/format.h>

#include <iostream>

#include "cli_util.hpp"
#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/fill/paper_fill.hpp"
#include "clumpkit/geometry/shape_spec.hpp"

namespace clumpkit::cli {
namespace {

struct FillArgs {
  std::string shape, method = "paper", out, axial, radius_rule;
  int spheres = 0, layers = 0, per_ring = -1;
  std::int64_t rays = RaySamplingOptions{}.rays;
  std::uint64_t seed = 1;
};

Command setup(CLI::App& parent) {
  auto args = std::make_shared<FillArgs>();
  CLI::App* c = parent.add_subcommand("fill", "Fill a shape with a sphere clump and write a "
                                              "clumpkit-clump/1 template (JSON, SI units)");
  c->add_option("SHAPE", args->shape, "Shape file (shapes/*.toml) or bundled name (pill_A)")
      ->required();
  c->add_option("--method", args->method, "Fill method: paper (tangency rules, cylinders)")
      ->check(CLI::IsMember({"paper"}));
  c->add_option("--spheres", args->spheres, "Number of spheres (paper presets: flat 4/12/20, "
                                            "tall 2/12/18)");
  c->add_option("--layers", args->layers, "Custom paper rule: number of layers");
  c->add_option("--per-ring", args->per_ring, "Custom paper rule: spheres per ring (0: none)");
  c->add_option("--axial", args->axial, "Custom paper rule: axial spheres none|outer|all")
      ->check(CLI::IsMember({"none", "outer", "all"}));
  c->add_option("--radius-rule", args->radius_rule,
                "Custom paper rule: sphere radius from height (H/(k+1)) or diameter (D/2)")
      ->check(CLI::IsMember({"height", "diameter"}));
  c->add_option("--rays", args->rays, "Rays for the union's mass properties")
      ->check(CLI::PositiveNumber);
  c->add_option("--seed", args->seed, "Seed of the ray jitter");
  c->add_option("-o,--output", args->out, "Output template (.json)")->required();
  return {c, [args] {
            check_writable(args->out, "--output");
            const ShapeSpec shape = load_shape(resolve_shape(args->shape));
            PaperFillRequest req;
            req.spheres = args->spheres;
            if (args->layers > 0 || args->per_ring >= 0 || !args->axial.empty() ||
                !args->radius_rule.empty()) {
              PaperRule r;
              if (args->layers > 0) r.layers = args->layers;
              if (args->per_ring >= 0) r.per_ring = args->per_ring;
              if (args->axial == "outer") r.axial = PaperRule::Axial::Outer;
              if (args->axial == "all") r.axial = PaperRule::Axial::All;
              if (args->radius_rule == "diameter") r.radius_rule = PaperRule::Radius::Diameter;
              req.custom = r;
            } else if (args->spheres <= 0) {
              throw InputError("", "--spheres", "give a sphere count (or a custom rule)");
            }
            req.sampling.rays = args->rays;
            req.sampling.seed = args->seed;
            ClumpTemplate clump = paper_fill_template(shape, req);
            save_clump(clump, args->out);
            std::cout << fmt::format("{}: {} spheres, union volume {:.4g} mm^3, mass {:.4g} g -> {}\n",
                                     clump.name, clump.spheres.size(), clump.mass.volume * 1e9,
                                     clump.mass.mass * 1e3, args->out);
            return 0;
          }};
}

const Registration reg(10, setup);

}  // namespace
}  // namespace clumpkit::cli
