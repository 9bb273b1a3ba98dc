#pragma once
// Shared by the export tests: a paper-filled pill template (built once) and small file helpers.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "clumpkit/fill/fill_problem.hpp"
#include "clumpkit/fill/paper_fill.hpp"
#include "clumpkit/fill/shape_library.hpp"
#include "clumpkit/geometry/clump_template.hpp"
#include "clumpkit/geometry/shape_spec.hpp"

namespace clumpkit::test {

/// Pill B (D 6.0 mm, H 5.8 mm, 1380 kg/m^3) filled with the paper's 12-sphere rule.
inline const ClumpTemplate& pill_template() {
  static const ClumpTemplate t = [] {
    PaperFillRequest req;
    req.spheres = 12;
    ClumpTemplate c = paper_fill_template(cylinder_shape("pill_B", 6.0e-3, 5.8e-3, 1380.0), req);
    c.name = "pill_B_12";
    return c;
  }();
  return t;
}

/// An asymmetric clump: the bundled rock filled by the EDT baseline with 8 spheres of unequal
/// radii (no symmetry puts its centre of mass or principal axes anywhere special).
inline const ClumpTemplate& asymmetric_template() {
  static const ClumpTemplate t = [] {
    auto solid = make_test_shape("rock");
    FillShape shape{solid, nullptr, "rock"};
    if (solid->has_exact_distance())
      shape.exact_distance = [solid](const Eigen::Vector3d& p) {
        return solid->signed_distance(p);
      };
    FillOptions o;
    o.spheres = 8;
    const FillResult r = edt_fill(shape, o);
    RaySamplingOptions sampling;
    const FillMeasurement m = measure_fill(shape, r.spheres, sampling);
    ClumpTemplate c = fill_template("edt", o, r, m, 1380.0, sampling);
    c.name = "rock_edt_8";
    return c;
  }();
  return t;
}

/// A template with a non-trivial frame: the pill template with a made-up rotation about a tilted
/// axis and a translation, so the recorded transform is distinguishable from the identity.
inline ClumpTemplate rotated_template() {
  ClumpTemplate c = pill_template();
  c.name = "tilted";
  c.rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  c.translation = Eigen::Vector3d(1.5e-3, -2.25e-3, 4e-4);
  return c;
}

/// A fresh, empty folder under the build tree, unique per test.
inline std::filesystem::path scratch_dir(const std::string& tag) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::filesystem::path d =
      std::filesystem::path(CLUMPKIT_BINARY_DIR) / "test_scratch" / "export" /
      (std::string(info->test_suite_name()) + "." + info->name() + (tag.empty() ? "" : "." + tag));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

/// Numbers on a line, separated by blanks and/or commas.
inline std::vector<double> numbers(std::string line) {
  for (char& ch : line)
    if (ch == ',') ch = ' ';
  std::istringstream in(line);
  std::vector<double> v;
  for (std::string tok; in >> tok;) v.push_back(std::stod(tok));
  return v;
}

/// Files (relative paths) below a folder, sorted.
inline std::vector<std::string> listing(const std::filesystem::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    out.push_back(std::filesystem::relative(e.path(), dir).string());
  std::sort(out.begin(), out.end());
  return out;
}

inline void expect_rel(double got, double want, double tol, const std::string& what) {
  const double scale = std::max(std::abs(want), 1e-300);
  EXPECT_LE(std::abs(got - want) / scale, tol) << what << ": got " << got << ", want " << want;
}

}  // namespace clumpkit::test
