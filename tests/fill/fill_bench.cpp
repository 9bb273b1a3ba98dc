// fill_bench: the comparison table of issue 4 (not part of the default test run).
//   fill_bench [--shapes a,b,...] [--counts 4,8,...] [--methods edt,optimal,paper] [--ratio E]
// Prints, per shape x method x sphere count, the symmetric-difference error measured on
// independent rays (95 % half-width) and the fill time; with --ratio E, the sphere counts each
// method needs to reach the error target E and their ratio.
#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "clumpkit/fill/fill_problem.hpp"
#include "clumpkit/fill/paper_rule.hpp"
#include "clumpkit/fill/shape_library.hpp"

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
}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> shapes = test_shape_names();
  std::vector<int> counts = {4, 8, 12, 20, 50, 100};
  std::vector<std::string> methods = {"paper", "edt", "optimal"};
  double ratio_target = 0.0, tolerance = -1.0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--shapes") shapes = split(v);
    if (k == "--methods") methods = split(v);
    if (k == "--ratio") ratio_target = std::atof(v.c_str());
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
  for (const std::string& name : shapes) {
    const FillShape shape = fill_shape(name);
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
        std::fflush(stdout);
      }
    }
    if (ratio_target > 0) {
      int need[2] = {0, 0};
      for (int k = 0; k < 2; ++k) {
        FillOptions o;
        o.max_error = ratio_target;
        o.tolerance = tolerance;
        const FillResult r = k == 0 ? edt_fill(shape, o) : optimal_fill(shape, o);
        need[k] = r.target_reached ? static_cast<int>(r.spheres.size()) : -1;
      }
      fmt::print("{:<18} target {:.3f}: edt {} spheres, optimal {} spheres, ratio {:.2f}\n", name,
                 ratio_target, need[0], need[1],
                 need[0] > 0 && need[1] > 0 ? static_cast<double>(need[0]) / need[1] : 0.0);
    }
  }
  return 0;
}
