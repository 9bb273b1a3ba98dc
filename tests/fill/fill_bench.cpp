// fill_bench: the comparison table of issue 4 (not part of the default test run).
//   fill_bench [--shapes a,b,...] [--counts 4,8,...] [--methods edt,optimal,paper]
//              [--ratio E1,E2,...] [--tolerance T] [--svg FILE] [--mesh FILE.stl]
// Prints, per shape x method x sphere count, the symmetric-difference error measured on
// independent rays (95 % half-width) and the fill time; with --ratio, the sphere counts each
// method needs to reach each error target and their ratio (each fill's error on the independent
// rays in brackets); with --svg, a plot of error against
// sphere count per method (one panel per shape); with --mesh, fills a mesh file (metres) through
// Embree instead of the test shapes.
#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "clumpkit/fill/fill_problem.hpp"
#include "clumpkit/fill/paper_rule.hpp"
#include "clumpkit/fill/shape_library.hpp"
#ifdef CLUMPKIT_BENCH_MESHES
#include "clumpkit/raycast/target_shape.hpp"
#endif

using namespace clumpkit;

namespace {
std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}
FillShape fill_shape(const std::string& name) {
  auto solid = make_test_shape(name);
  FillShape s{solid, nullptr, name};
  if (solid->has_exact_distance())
    s.exact_distance = [solid](const Eigen::Vector3d& p) { return solid->signed_distance(p); };
  return s;
}
FillShape mesh_shape(const std::string& path) {
#ifdef CLUMPKIT_BENCH_MESHES
  TargetShape t = target_from_mesh(path, 1.0);
  std::shared_ptr<const SurfaceSolid> solid(std::move(t.solid));
  return fill_shape_with_surface_distance(solid, path);  // as clumpkit fill does
#else
  (void)path;
  std::fprintf(stderr, "fill_bench: built without mesh support\n");
  std::exit(2);
#endif
}

// Error against sphere count, one panel per shape, one polyline per method (log-log axes).
using Series = std::map<std::string, std::map<std::string, std::vector<std::pair<int, double>>>>;
void write_svg(const std::string& path, const std::vector<std::string>& shapes, const Series& data,
               const std::vector<int>& counts) {
  const int cols = 4, pw = 260, ph = 200, ml = 46, mb = 30, mt = 22;
  const int rows = (static_cast<int>(shapes.size()) + cols - 1) / cols;
  std::ofstream o(path);
  o << "<svg xmlns='http://www.w3.org/2000/svg' width='" << cols * pw << "' height='"
    << rows * ph + 30 << "' font-family='sans-serif' font-size='10'>\n"
    << "<rect width='100%' height='100%' fill='white'/>\n";
  const std::map<std::string, std::string> colour = {
      {"paper", "#2ca02c"}, {"edt", "#d62728"}, {"optimal", "#1f77b4"}};
  int cmin = 1 << 30, cmax = 1;
  for (int c : counts) cmin = std::min(cmin, c), cmax = std::max(cmax, c);
  const double lx0 = std::log(std::max(1, cmin)), lx1 = std::log(std::max(cmin + 1, cmax));
  const double ly0 = std::log(0.005), ly1 = std::log(1.0);
  for (size_t k = 0; k < shapes.size(); ++k) {
    const int ox = static_cast<int>(k % cols) * pw, oy = static_cast<int>(k / cols) * ph;
    const double w = pw - ml - 10, h = ph - mb - mt;
    auto X = [&](double c) { return ox + ml + w * (std::log(c) - lx0) / (lx1 - lx0); };
    auto Y = [&](double e) {
      const double le = std::clamp(std::log(std::max(e, 1e-9)), ly0, ly1);
      return oy + mt + h * (ly1 - le) / (ly1 - ly0);
    };
    o << fmt::format("<text x='{}' y='{}' font-weight='bold'>{}</text>\n", ox + ml, oy + 14,
                     shapes[k]);
    o << fmt::format("<rect x='{}' y='{}' width='{}' height='{}' fill='none' stroke='#888'/>\n",
                     ox + ml, oy + mt, w, h);
    for (double e : {0.01, 0.03, 0.1, 0.3, 1.0})
      o << fmt::format("<text x='{}' y='{:.1f}' text-anchor='end'>{}</text>\n", ox + ml - 3,
                       Y(e) + 3, e);
    for (int c : counts)
      o << fmt::format("<text x='{:.1f}' y='{}' text-anchor='middle'>{}</text>\n", X(c),
                       oy + mt + h + 12, c);
    auto it = data.find(shapes[k]);
    if (it == data.end()) continue;
    for (const auto& [method, pts] : it->second) {
      std::string poly;
      for (const auto& [c, e] : pts) poly += fmt::format("{:.1f},{:.1f} ", X(c), Y(e));
      const std::string col = colour.count(method) ? colour.at(method) : "#000";
      o << fmt::format("<polyline points='{}' fill='none' stroke='{}' stroke-width='1.5'/>\n", poly,
                       col);
      for (const auto& [c, e] : pts)
        o << fmt::format("<circle cx='{:.1f}' cy='{:.1f}' r='2.5' fill='{}'/>\n", X(c), Y(e), col);
    }
  }
  int lx = 10;
  for (const auto& [m, col] : colour) {
    o << fmt::format("<rect x='{}' y='{}' width='12' height='4' fill='{}'/>", lx, rows * ph + 12,
                     col)
      << fmt::format("<text x='{}' y='{}'>{}</text>\n", lx + 16, rows * ph + 17, m);
    lx += 80;
  }
  o << fmt::format(
           "<text x='{}' y='{}'>symmetric-difference error |S xor U|/|S| (log) against "
           "sphere count (log), measured on 10^6 independent rays</text>\n",
           lx + 10, rows * ph + 17)
    << "</svg>\n";
}
}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> shapes = test_shape_names();
  std::vector<int> counts = {4, 8, 12, 20, 50, 100};
  std::vector<std::string> methods = {"paper", "edt", "optimal"};
  std::vector<double> ratio_targets;
  double tolerance = -1.0;
  std::string svg, mesh;
  const char* usage =
      "usage: fill_bench [--shapes a,b,...] [--counts 4,8,...] [--methods edt,optimal,paper]\n"
      "                  [--ratio E1,E2,...] [--tolerance T] [--svg FILE] [--mesh FILE.stl]\n";
  const std::set<std::string> keys = {"--shapes", "--methods", "--ratio",    "--svg",
                                      "--mesh",   "--counts",  "--tolerance"};
  for (int i = 1; i < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--help" || k == "-h") {
      std::cout << usage;
      return 0;
    }
    if (!keys.count(k) || i + 1 >= argc) {
      std::cerr << "fill_bench: " << (keys.count(k) ? "no value for " : "unknown option ") << k
                << "\n"
                << usage;
      return 2;
    }
    const std::string v = argv[i + 1];
    if (k == "--shapes") shapes = split(v);
    if (k == "--methods") methods = split(v);
    if (k == "--ratio")
      for (const auto& e : split(v)) ratio_targets.push_back(std::atof(e.c_str()));
    if (k == "--svg") svg = v;
    if (k == "--mesh") mesh = v;
    if (k == "--tolerance") tolerance = std::atof(v.c_str());
    if (k == "--counts") {
      counts.clear();
      for (const auto& c : split(v)) counts.push_back(std::atoi(c.c_str()));
    }
  }
  RaySamplingOptions measure;
  measure.rays = 1'000'000;
  measure.seed = 12345;
  fmt::print("{:<18} {:<8} {:>7} {:>14} {:>10} {:>8}\n", "shape", "method", "spheres", "sym.diff",
             "ci95", "time s");
  if (!mesh.empty()) shapes = {mesh};
  Series series;
  for (const std::string& name : shapes) {
    const FillShape shape = mesh.empty() ? fill_shape(name) : mesh_shape(mesh);
    for (const std::string& method : methods) {
      for (int n : counts) {
        Spheres spheres;
        const auto t0 = std::chrono::steady_clock::now();
        if (method == "paper") {
          if (name.rfind("pill_", 0) != 0 || name.find("chamfered") != std::string::npos) continue;
          const double h = name == "pill_A" ? 5.4e-3 : name == "pill_B" ? 5.8e-3 : 6.2e-3;
          const CylinderRegime rg = regime(6e-3, h);
          const auto avail = paper_preset_counts(rg);
          if (std::find(avail.begin(), avail.end(), n) == avail.end()) continue;
          spheres = paper_fill(6e-3, h, paper_preset(rg, n));
        } else {
          FillOptions o;
          o.spheres = n;
          o.tolerance = tolerance;
          const FillResult r = method == "edt" ? edt_fill(shape, o) : optimal_fill(shape, o);
          spheres = r.spheres;
          if (std::getenv("FILL_BENCH_VERBOSE")) std::cerr << r.report.dump() << "\n";
        }
        const double secs =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const FillMeasurement m = measure_fill(shape, spheres, measure);
        fmt::print("{:<18} {:<8} {:>7} {:>14.5f} {:>10.5f} {:>8.2f}\n", name, method,
                   spheres.size(), m.symmetric_difference.value, m.symmetric_difference.ci95, secs);
        series[name][method].emplace_back(n, m.symmetric_difference.value);
        std::fflush(stdout);
      }
    }
    for (const double ratio_target : ratio_targets) {
      int need[2] = {0, 0};
      double measured[2] = {0.0, 0.0};  // on the independent rays, not the fill's own
      for (int k = 0; k < 2; ++k) {
        FillOptions o;
        o.max_error = ratio_target;
        o.tolerance = tolerance;
        const FillResult r = k == 0 ? edt_fill(shape, o) : optimal_fill(shape, o);
        need[k] = r.target_reached ? static_cast<int>(r.spheres.size()) : -1;
        measured[k] = measure_fill(shape, r.spheres, measure).symmetric_difference.value;
      }
      fmt::print(
          "{:<18} target {:.3f}: edt {} spheres ({:.4f}), optimal {} spheres ({:.4f}), "
          "ratio {:.2f}\n",
          name, ratio_target, need[0], measured[0], need[1], measured[1],
          need[0] > 0 && need[1] > 0 ? static_cast<double>(need[0]) / need[1] : 0.0);
      std::fflush(stdout);
    }
  }
  if (!svg.empty()) write_svg(svg, shapes, series, counts);
  return 0;
}
