// clumpkit error CLUMP.json [--shape SHAPE|MESH]: how far a clump is from its shape, by ray
// sampling (volume, centre of mass, inertia, symmetric difference, surface distances, each
// sampled figure with its 95 % interval). --table: several clumps in one sorted table + a plot.
#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <map>

#include "cli_util.hpp"
#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/core/units.hpp"
#include "clumpkit/fill/shape_library.hpp"
#include "clumpkit/geometry/clump_template.hpp"
#include "clumpkit/raycast/mesh_solid.hpp"
#include "clumpkit/raycast/shape_error.hpp"
#include "clumpkit/raycast/target_shape.hpp"

namespace clumpkit::cli {
namespace {

struct ErrorArgs {
  std::vector<std::string> clumps;
  std::string shape, mesh_units = "m", json, plot;
  std::int64_t rays = RaySamplingOptions{}.rays;
  std::uint64_t seed = 1;
  std::size_t samples = ShapeErrorOptions{}.surface_samples;
  int replicates = RaySamplingOptions{}.replicates;
  bool table = false;
  MeshRepairFlags repairs;  // for --shape; a template's recorded mesh: as it was filled
};

struct Row {
  std::string clump, name, shape;
  ShapeError e;
};

// A bundled test shape (torus, pill_C_chamfered, ...: `clumpkit mesh --list`), measured through
// its tessellation at 100 000 triangles (the committed meshes have 2000): its volume is within
// 0.06 % of the exact shape's (torus 0.035 %, chamfered pill C 0.06 %; flat-faced shapes
// exact). The rock's shape depends on its seed.
constexpr int kTestShapeTriangles = 100000;

TargetShape target_from_test_shape(const std::string& name, std::uint64_t seed) {
  const TessellatedMesh t = make_test_shape(name, seed)->tessellate(kTestShapeTriangles);
  TriangleMesh mesh;
  mesh.vertices = t.vertices;
  for (const auto& tri : t.triangles) mesh.triangles.emplace_back(tri[0], tri[1], tri[2]);
  TargetShape target;
  target.description = fmt::format("{}: bundled test shape, tessellated ({} triangles)", name,
                                   mesh.triangles.size());
  target.solid = std::make_unique<MeshSolid>(std::move(mesh));
  return target;
}

Row analyse(const std::string& path, const ErrorArgs& a) {
  const ClumpTemplate clump = load_clump(path);
  TargetShape target;
  const nlohmann::json& src = clump.source;
  auto text = [&](const char* key) {
    const auto it = src.is_object() ? src.find(key) : src.end();
    return it != src.end() && it->is_string() ? it->get<std::string>() : std::string();
  };
  if (a.shape.empty() && text("kind") == "test_shape" && is_test_shape(text("shape"))) {
    const auto seed = src.find("seed");  // older templates have none: the default, 1
    target = target_from_test_shape(text("shape"), seed != src.end() && seed->is_number_unsigned()
                                                       ? seed->get<std::uint64_t>()
                                                       : std::uint64_t{1});
  } else if (a.shape.empty()) {
    target = target_from_source(clump, path);
  } else if (!is_mesh_file(a.shape) && is_test_shape(a.shape) &&
             !path_exists(data_dir() / "shapes" / (a.shape + ".toml"))) {
    target = target_from_test_shape(a.shape, 1);
  } else if (is_mesh_file(a.shape)) {
    MeshLoadOptions load;
    load.scale = unit_factor(a.mesh_units, Dimension::Length, "", "--mesh-units");
    a.repairs.apply(load);
    target = target_from_mesh(a.shape, load);
    warn_if_mesh_units_suspect(a.shape, target.solid->bounds().sizes().maxCoeff(), a.mesh_units);
  } else {
    ShapeSpec spec = load_shape(resolve_shape(a.shape));
    a.repairs.apply(spec);
    target = target_from_shape(spec);
  }
  ShapeErrorOptions opt;
  opt.sampling.rays = a.rays;
  opt.sampling.seed = a.seed;
  opt.sampling.replicates = a.replicates;
  opt.surface_samples = a.samples;
  opt.density = target.density > 0 ? target.density : clump.mass.density;
  Row r;
  r.clump = path;
  r.name = clump.name.empty() ? path : clump.name;
  r.shape = target.description;
  // The template's spheres live in its centroid-principal frame; the shape in its own.
  try {
    r.e = shape_error(*target.solid, clump.spheres_in_source_frame(), opt);
  } catch (const InputError& e) {
    throw e.where().empty() ? e.at(path) : e;
  }
  return r;
}

void print_one(const Row& r) {
  const ShapeError& e = r.e;
  auto pct = [](const Estimate& x) {
    return fmt::format("{:+.3f} % ± {:.3f} %", 100 * x.value, 100 * x.ci95);
  };
  std::cout << fmt::format("clump       {} ({} spheres)\n", r.name, e.spheres);
  std::cout << fmt::format("shape       {}\n", r.shape);
  std::cout << fmt::format(
      "sampling    {} rays, {} replicates x 3 axes, seed {}; {} surface "
      "points each; {:.2f} s\n",
      e.rays, e.replicates, e.seed, e.surface_samples, e.seconds);
  std::cout << "            (± = 95 % confidence half-width from the replicates)\n";
  std::cout << fmt::format("volume      shape {:.6g} mm^3 ± {:.2g}   clump {:.6g} mm^3 ± {:.2g}\n",
                           e.shape.volume * 1e9, e.shape_ci.volume * 1e9, e.clump.volume * 1e9,
                           e.clump_ci.volume * 1e9);
  std::cout << fmt::format("            clump vs shape {}\n", pct(e.volume_rel_error));
  std::cout << fmt::format("sym. diff.  {:.6g} mm^3 ± {:.2g} = {:.3f} % ± {:.3f} % of the shape\n",
                           e.sym_diff_volume.value * 1e9, e.sym_diff_volume.ci95 * 1e9,
                           100 * e.sym_diff_rel.value, 100 * e.sym_diff_rel.ci95);
  std::cout << fmt::format(
      "COM offset  {:.4g} mm ± {:.2g} = {:.4f} % ± {:.4f} % of the shape's "
      "equivalent-sphere diameter {:.4g} mm\n",
      e.com_offset.value * 1e3, e.com_offset.ci95 * 1e3, 100 * e.com_offset_rel.value,
      100 * e.com_offset_rel.ci95, e.size * 1e3);
  std::cout << fmt::format("density     {:.6g} kg/m^3; mass shape {:.6g} g, clump {:.6g} g\n",
                           e.shape.density, e.shape.mass * 1e3, e.clump.mass * 1e3);
  std::cout << "principal   shape (g mm^2)    clump (g mm^2)    clump vs shape\n";
  for (int k = 0; k < 3; ++k)
    std::cout << fmt::format("  I{}        {:<17.6g} {:<17.6g} {}\n", k + 1,
                             e.shape.principal_moments[k] * 1e9, e.clump.principal_moments[k] * 1e9,
                             pct(e.moments_rel_error[k]));
  if (e.axis_angle_deg)
    std::cout << fmt::format("axis angle  {:.3f} deg (over {} distinct principal axes)\n",
                             *e.axis_angle_deg, e.axes_compared);
  else
    std::cout << "axis angle  n/a (no principal moment is distinct: axes are arbitrary)\n";
  std::cout << fmt::format(
      "surface     Hausdorff {:.4f} mm, mean distance {:.4f} mm "
      "(shape->clump max {:.4f} mean {:.4f}; clump->shape max {:.4f} mean "
      "{:.4f} mm)\n",
      e.hausdorff * 1e3, e.mean_surface_distance * 1e3, e.shape_to_clump_max * 1e3,
      e.shape_to_clump_mean * 1e3, e.clump_to_shape_max * 1e3, e.clump_to_shape_mean * 1e3);
  if (e.unresolved_lines > 0)
    std::cout << fmt::format("warning     {} mesh lines could not be resolved and were left out\n",
                             e.unresolved_lines);
}

std::string shape_key(const Row& r) {
  return r.shape.substr(0, r.shape.find(':'));
}

// Symmetric-difference error against sphere count, one line per shape: a small hand-written SVG.
std::string plot_svg(const std::vector<Row>& rows) {
  const double W = 640, H = 420, L = 70, R = 150, T = 40, B = 60;
  double xmax = 1, ymax = 0;
  std::map<std::string, std::vector<std::pair<double, double>>> series;
  for (const Row& r : rows) {
    const double y = 100 * r.e.sym_diff_rel.value;
    series[shape_key(r)].push_back({static_cast<double>(r.e.spheres), y});
    xmax = std::max(xmax, static_cast<double>(r.e.spheres));
    ymax = std::max(ymax, y);
  }
  xmax = std::ceil(xmax / 4.0) * 4.0;
  ymax = std::max(1.0, std::ceil(ymax / 5.0) * 5.0);
  auto X = [&](double x) { return L + (W - L - R) * x / xmax; };
  auto Y = [&](double y) { return H - B - (H - T - B) * y / ymax; };
  std::string s = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" "
      "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" "
      "fill=\"white\"/>\n<text x=\"{}\" y=\"22\" font-size=\"15\">Shape error of the clumps: "
      "symmetric difference vs sphere count</text>\n",
      W, H, L, 0);
  s += fmt::format("<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"black\"/>\n", L, Y(0),
                   X(xmax), Y(0));
  s += fmt::format("<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"black\"/>\n", L, Y(0), L,
                   Y(ymax));
  for (int i = 0; i <= 4; ++i) {
    const double x = xmax * i / 4, y = ymax * i / 4;
    s += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">{:g}</text>\n", X(x),
                     Y(0) + 18, x);
    s += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"end\">{:g}</text>\n", L - 6,
                     Y(y) + 4, y);
    s +=
        fmt::format("<line x1=\"{}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#ddd\"/>\n",
                    L, Y(y), X(xmax), Y(y));
  }
  s += fmt::format(
      "<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">spheres in the "
      "clump</text>\n",
      X(xmax / 2), H - 18);
  s += fmt::format(
      "<text x=\"18\" y=\"{:.1f}\" text-anchor=\"middle\" transform=\"rotate(-90 18 "
      "{:.1f})\">|shape XOR clump| / V_shape (%)</text>\n",
      Y(ymax / 2), Y(ymax / 2));
  const char* colours[] = {"#1b6ca8", "#d1495b", "#2e933c", "#edae49", "#66462c", "#7b2cbf"};
  int c = 0;
  for (auto& [name, pts] : series) {
    std::sort(pts.begin(), pts.end());
    const char* col = colours[c % 6];
    std::string path;
    for (const auto& [x, y] : pts) path += fmt::format("{:.1f},{:.1f} ", X(x), Y(y));
    s += fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>\n",
                     path, col);
    for (const auto& [x, y] : pts)
      s += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"4\" fill=\"{}\"/>\n", X(x), Y(y),
                       col);
    s += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"14\" height=\"4\" fill=\"{}\"/>\n",
                     W - R + 16, T + 20 + 20 * c, col);
    s += fmt::format("<text x=\"{}\" y=\"{}\">{}</text>\n", W - R + 36, T + 26 + 20 * c, name);
    ++c;
  }
  return s + "</svg>\n";
}

void print_table(std::vector<Row>& rows) {
  std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) {
    return std::make_tuple(shape_key(a), a.e.spheres, a.name) <
           std::make_tuple(shape_key(b), b.e.spheres, b.name);
  });
  std::cout << fmt::format("{:<14} {:<10} {:>7} {:>15} {:>15} {:>9} {:>9} {:>8} {:>9} {:>9}\n",
                           "clump", "shape", "spheres", "dV/V (%)", "XOR/V (%)", "dCOM/d",
                           "max dI/I", "axis", "Hausdorff", "mean dist");
  std::cout << fmt::format("{:<14} {:<10} {:>7} {:>15} {:>15} {:>9} {:>9} {:>8} {:>9} {:>9}\n", "",
                           "", "", "± 95 %", "± 95 %", "(%)", "(%)", "(deg)", "(mm)", "(mm)");
  for (const Row& r : rows) {
    const ShapeError& e = r.e;
    double worst = 0;
    for (const Estimate& m : e.moments_rel_error)
      worst = std::abs(m.value) > std::abs(worst) ? m.value : worst;
    std::cout << fmt::format(
        "{:<14} {:<10} {:>7} {:>15} {:>15} {:>9.4f} {:>+9.2f} {:>8} {:>9.4f} {:>9.4f}\n", r.name,
        shape_key(r), e.spheres,
        fmt::format("{:+.2f} ± {:.3f}", 100 * e.volume_rel_error.value,
                    100 * e.volume_rel_error.ci95),
        fmt::format("{:.2f} ± {:.3f}", 100 * e.sym_diff_rel.value, 100 * e.sym_diff_rel.ci95),
        100 * e.com_offset_rel.value, 100 * worst,
        e.axis_angle_deg ? fmt::format("{:.2f}", *e.axis_angle_deg) : std::string("n/a"),
        e.hausdorff * 1e3, e.mean_surface_distance * 1e3);
  }
  std::cout << "dV/V: clump union vs shape volume; XOR/V: symmetric difference / shape volume; "
               "dCOM/d: centre-of-mass offset / equivalent-sphere diameter;\nmax dI/I: largest "
               "principal-moment error; axis: principal-axis angle over distinct axes.\n";
}

Command setup_error(CLI::App& parent) {
  auto a = std::make_shared<ErrorArgs>();
  CLI::App* c = parent.add_subcommand(
      "error",
      "Shape error of a clump against its shape (or --shape): volume, centre of mass, "
      "inertia, symmetric difference, Hausdorff and mean surface distance, with 95 % "
      "intervals, by ray sampling (SI units)");
  c->add_option("CLUMP", a->clumps, "Clump template(s) (.json); several with --table")
      ->required()
      ->check(CLI::ExistingFile);
  c->add_option("--shape", a->shape,
                "Shape to compare with: a shape file (shapes/*.toml), a bundled name (pill_A, or a "
                "test shape of `clumpkit mesh --list`: torus) or "
                "a closed mesh (.stl .obj .ply .off); default: the template's recorded source");
  c->add_option("--mesh-units", a->mesh_units, "Length unit of a --shape mesh file (m, mm, ...)");
  a->repairs.add_to(c, "with --shape (a template's recorded mesh is read as it was filled)");
  c->add_option("--rays", a->rays, "Rays in total (3 axes x replicates)")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{2'000'000'000}));
  c->add_option("--seed", a->seed, "Seed of the ray jitter and surface samples");
  c->add_option("--replicates", a->replicates, "Independent jittered grids per axis (>= 2)")
      ->check(CLI::Range(2, 30));
  c->add_option("--samples", a->samples, "Surface points per surface for the distances")
      ->check(CLI::Range(std::size_t{1}, std::size_t{100'000'000}));
  c->add_option("--json", a->json, "Write the figures as JSON (FILE or -)");
  c->add_flag("--table", a->table,
              "Tabulate several clumps, sorted by shape and sphere count, "
              "and plot symmetric difference vs sphere count (--plot)");
  c->add_option("--plot", a->plot,
                "With --table: the SVG plot to write (default "
                "shape_error.svg)");
  return {c, [a] {
            if (!a->table && a->clumps.size() != 1)
              throw InputError("", "CLUMP", "give one clump (or --table for several)");
            if (!a->plot.empty() && !a->table) throw InputError("", "--plot", "only with --table");
            if (!a->json.empty() && a->json != "-") check_writable(a->json, "--json");
            const std::string plot = a->plot.empty() ? "shape_error.svg" : a->plot;
            if (a->table) check_writable(plot, "--plot");
            std::vector<Row> rows;
            for (const std::string& p : a->clumps) rows.push_back(analyse(p, *a));
            if (!a->table) {
              if (a->json != "-") print_one(rows[0]);
              if (!a->json.empty()) {
                nlohmann::json j = to_json(rows[0].e);
                j["clump"] = rows[0].clump;
                j["shape"] = rows[0].shape;
                write_json(j, a->json);
              }
              return 0;
            }
            if (a->json != "-") print_table(rows);
            write_file_atomic(plot, plot_svg(rows));
            if (a->json != "-") std::cout << "plot -> " << plot << "\n";
            if (!a->json.empty()) {
              nlohmann::json arr = nlohmann::json::array();
              for (const Row& r : rows) {
                nlohmann::json j = to_json(r.e);
                j["clump"] = r.clump;
                j["name"] = r.name;
                j["shape"] = r.shape;
                arr.push_back(j);
              }
              write_json(arr, a->json);
            }
            return 0;
          }};
}

const Registration reg_error(30, setup_error);

}  // namespace
}  // namespace clumpkit::cli
