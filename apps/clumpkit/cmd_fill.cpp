// clumpkit fill SHAPE --method paper --spheres N -o OUT.json
// clumpkit fill SHAPE|MESH|TEST_SHAPE --method edt|optimal (--spheres N | --max-error E)
//              -o OUT.json
#include <fmt/format.h>

#include <iostream>

#include "cli_util.hpp"
#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/core/units.hpp"
#include "clumpkit/fill/fill_problem.hpp"
#include "clumpkit/fill/paper_fill.hpp"
#include "clumpkit/fill/shape_library.hpp"
#include "clumpkit/geometry/cylinder.hpp"
#include "clumpkit/geometry/shape_spec.hpp"
#ifdef CLUMPKIT_HAVE_RAYCAST
#include "clumpkit/raycast/shape_error.hpp"
#include "clumpkit/raycast/target_shape.hpp"
#endif

namespace clumpkit::cli {
namespace {

struct FillArgs {
  std::string shape, method = "paper", out, axial, radius_rule;
  int spheres = 0, layers = 0, per_ring = -1;
  std::int64_t rays = RaySamplingOptions{}.rays;
  std::uint64_t seed = 1;
  // edt / optimal
  double max_error = 0.0;
  std::string metric = "symmetric_difference", min_radius, tolerance, mesh_units = "m", density;
  int grid = FillOptions{}.grid;
  MeshRepairFlags repairs;
};

// A note on stderr when the loader repaired the mesh (--repair-orientation, --repair-holes), a
// warning when the holes it closed are a large part of the surface (the shape is then partly
// invented: a bowl is closed by a lid), and one when the mesh is several separate pieces.
void note_mesh(const TargetShape& t) {
  if (t.solids > 1)
    std::cerr << fmt::format(
        "clumpkit: warning: {} holds {} separate solids: the clump will be one rigid particle "
        "made of all of them (fill each piece from its own file for separate particles)\n",
        t.description, t.solids);
  if (t.reoriented_faces == 0 && t.holes_filled == 0) return;
  std::cerr << fmt::format("clumpkit: note: repaired {}\n", t.description);
  if (t.hole_area_fraction > 0.05)
    std::cerr << fmt::format(
        "clumpkit: warning: the closed holes are {:.0f} % of the surface: the filled shape is "
        "partly made up; check it (clumpkit error, or the template's VTK export)\n",
        100 * t.hole_area_fraction);
}

// The shape of an edt/optimal fill: a mesh file, a shape file (or bundled shape), or a test shape
// of the library (`clumpkit mesh --list`). Sets `source` provenance and the density.
FillShape general_shape(const FillArgs& a, nlohmann::json& source, double& density) {
  namespace fs = std::filesystem;
  std::error_code ec;
#ifdef CLUMPKIT_HAVE_RAYCAST  // Embree is required (lib/src/raycast): every build has it
  if (is_mesh_file(a.shape)) {
    const double scale = unit_factor(a.mesh_units, Dimension::Length, "", "--mesh-units");
    MeshLoadOptions load;
    load.scale = scale;
    a.repairs.apply(load);
    TargetShape t = target_from_mesh(a.shape, load);
    note_mesh(t);
    warn_if_mesh_units_suspect(a.shape, t.solid->bounds().sizes().maxCoeff(), a.mesh_units);
    std::shared_ptr<const SurfaceSolid> solid(std::move(t.solid));
    source = {{"file", a.shape}, {"kind", "mesh"}, {"mesh_scale", scale}, {"units", a.mesh_units}};
    record_mesh_repairs(load, source);
    return fill_shape_with_surface_distance(solid, a.shape);
  }
#endif
  const bool is_test = is_test_shape(a.shape);
  bool have_file = fs::exists(a.shape, ec);
  if (!have_file && !is_test) have_file = true;  // let resolve_shape report the missing file
  if (!have_file || (is_test && !fs::exists(data_dir() / "shapes" / (a.shape + ".toml"), ec))) {
    auto solid = make_test_shape(a.shape, a.seed);
    FillShape s{solid, nullptr, a.shape};
    if (solid->has_exact_distance())
      s.exact_distance = [solid](const Eigen::Vector3d& p) { return solid->signed_distance(p); };
    source = {{"shape", a.shape},
              {"kind", "test_shape"},
              {"description", test_shape_description(a.shape)},
              {"seed", a.seed},  // the rock's shape depends on it
              {"volume", solid->volume()}};
    return s;
  }
  ShapeSpec spec = load_shape(resolve_shape(a.shape));
  a.repairs.apply(spec);
  density = spec.density;
  source = {{"shape", spec.name},
            {"file", spec.path.string()},
            {"density", spec.density},
            {"material", spec.material},
            {"mass_fraction", spec.mass_fraction}};
  if (spec.kind == ShapeSpec::Kind::Cylinder) {
    auto cyl = std::make_shared<Cylinder>(spec.diameter, spec.height);
    source["kind"] = "cylinder";
    source["diameter"] = spec.diameter;
    source["height"] = spec.height;
    FillShape s{cyl, nullptr, spec.path.string()};
    s.exact_distance = [cyl](const Eigen::Vector3d& p) { return cyl->signed_distance(p); };
    return s;
  }
#ifdef CLUMPKIT_HAVE_RAYCAST
  TargetShape t = target_from_shape(spec);
  note_mesh(t);
  std::shared_ptr<const SurfaceSolid> solid(std::move(t.solid));
  source["kind"] = "mesh";
  source["mesh"] = spec.mesh.string();
  source["mesh_scale"] = spec.mesh_scale;
  record_mesh_repairs(spec, source);
  return fill_shape_with_surface_distance(solid, spec.path.string());
#else
  throw InputError(spec.path.string(), "shape.kind", "this build has no mesh support (raycast)");
#endif
}

int run_general(const FillArgs& a) {
  check_writable(a.out, "--output");
  FillOptions o;
  o.spheres = a.spheres;
  o.max_error = a.max_error;
  o.metric = parse_fill_metric(a.metric);
  if (!a.min_radius.empty())
    o.min_radius = parse_quantity(a.min_radius, Dimension::Length, "", "--min-radius");
  if (!a.tolerance.empty())
    o.tolerance = parse_quantity(a.tolerance, Dimension::Length, "", "--tolerance");
  if (o.tolerance < -1.0 || (!a.tolerance.empty() && o.tolerance < 0))
    throw InputError("", "--tolerance", "must be zero or positive");
  o.grid = a.grid;
  o.seed = a.seed;
  validate_fill_options(o);
  nlohmann::json source;
  double density = 1380.0;
  const FillShape shape = general_shape(a, source, density);
  if (!a.density.empty()) density = parse_quantity(a.density, Dimension::Density, "", "--density");
  if (density <= 0) throw InputError("", "--density", "must be positive");
  const FillResult r = a.method == "edt" ? edt_fill(shape, o) : optimal_fill(shape, o);
  RaySamplingOptions sampling;
  sampling.rays = a.rays;
  sampling.seed = a.seed + 7919;  // independent of the fill's own rays
  const FillMeasurement m = measure_fill(shape, r.spheres, sampling);
  ClumpTemplate clump = fill_template(a.method, o, r, m, density, sampling);
  clump.name = fmt::format("{}_{}_{}", std::filesystem::path(a.shape).stem().string(), a.method,
                           r.spheres.size());
  clump.source = source;
  save_clump(clump, a.out);
  std::cout << fmt::format(
      "{}: {} spheres ({}), symmetric difference {:.4f} +- {:.4f}, volume error {:.4f}, inertia "
      "error {:.4f} (relative); union volume {:.4g} mm^3, mass {:.4g} g -> {}\n",
      clump.name, r.spheres.size(), a.method, m.symmetric_difference.value,
      m.symmetric_difference.ci95, m.volume.value, m.inertia.value, clump.mass.volume * 1e9,
      clump.mass.mass * 1e3, a.out);
  if (!r.target_reached) {
    std::cerr << fmt::format(
        "clumpkit: warning: target {} <= {} not reached with {} spheres (best {:.4f}); wrote the "
        "best found, marked method.target_reached = false\n",
        a.metric, a.max_error, r.spheres.size(), r.error);
    return 3;
  }
  return 0;
}

Command setup_fill(CLI::App& parent) {
  auto args = std::make_shared<FillArgs>();
  CLI::App* c = parent.add_subcommand("fill",
                                      "Fill a shape with a sphere clump and write a "
                                      "clumpkit-clump/1 template (JSON, SI units)");
  c->add_option("SHAPE", args->shape, "Shape file (shapes/*.toml) or bundled name (pill_A)")
      ->required();
  c->add_option("--method", args->method,
                "Fill method: paper (tangency rules, cylinders), edt (greedy largest inscribed "
                "sphere, baseline), optimal (optimiser; any shape or mesh)")
      ->check(CLI::IsMember({"paper", "edt", "optimal"}));
  c->add_option("--spheres", args->spheres,
                "Number of spheres (paper presets: flat 4/12/20, "
                "tall 2/12/18; edt/optimal: any, or the cap with "
                "--max-error)");
  c->add_option("--max-error", args->max_error,
                "edt/optimal: stop at this relative error on --metric (e.g. 0.05); exit 3 and "
                "the best found if unreachable");
  c->add_option("--metric", args->metric,
                "edt/optimal: error metric of --max-error: symmetric_difference (|S xor U|/|S|), "
                "volume, inertia (principal moments)")
      ->check(CLI::IsMember({"symmetric_difference", "volume", "inertia"}));
  c->add_option("--min-radius", args->min_radius,
                "edt/optimal: smallest sphere radius (\"0.2 mm\")");
  c->add_option("--tolerance", args->tolerance,
                "edt/optimal: how far a sphere may leave the shape (\"0.05 mm\"; default 1 % of "
                "the volume-equivalent diameter)");
  c->add_option("--mesh-units", args->mesh_units, "Length unit of a mesh file (m, mm, ...)");
  args->repairs.add_to(c, "edt/optimal");
  c->add_option("--density", args->density,
                "edt/optimal: density (\"1380 kg/m^3\"; default the shape file's, else 1380)");
  c->add_option("--grid", args->grid, "edt/optimal: distance-grid cells along the longest side")
      ->check(CLI::Range(16, 400));
  c->add_option("--layers", args->layers, "Custom paper rule: number of layers");
  c->add_option("--per-ring", args->per_ring, "Custom paper rule: spheres per ring (0: none)");
  c->add_option("--axial", args->axial, "Custom paper rule: axial spheres none|outer|all")
      ->check(CLI::IsMember({"none", "outer", "all"}));
  c->add_option("--radius-rule", args->radius_rule,
                "Custom paper rule: sphere radius from height (H/(k+1)) or diameter (D/2)")
      ->check(CLI::IsMember({"height", "diameter"}));
  c->add_option("--rays", args->rays, "Rays for the union's mass properties")
      ->check(CLI::PositiveNumber);
  c->add_option("--seed", args->seed, "Seed of the ray jitter (and of the optimiser's rays)");
  c->add_option("-o,--output", args->out, "Output template (.json)")->required();
  return {c, [args] {
            if (args->method != "paper") return run_general(*args);
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
#ifdef CLUMPKIT_HAVE_RAYCAST
            {  // shape-error figures against the exact cylinder (raycast/shape_error.hpp)
              ShapeErrorOptions eo;
              eo.sampling = req.sampling;
              record_shape_error(clump, *target_from_shape(shape).solid, eo);
            }
#endif
            save_clump(clump, args->out);
            std::cout << fmt::format(
                "{}: {} spheres, union volume {:.4g} mm^3, mass {:.4g} g -> {}\n", clump.name,
                clump.spheres.size(), clump.mass.volume * 1e9, clump.mass.mass * 1e3, args->out);
            return 0;
          }};
}

const Registration reg_fill(10, setup_fill);

}  // namespace
}  // namespace clumpkit::cli
