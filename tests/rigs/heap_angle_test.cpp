// The angle measurement on synthetic heaps: cones of spheres with a known angle are measured
// within 1°, in both fit windows, from every viewing direction; detached pills and a skirt do
// not move it; a flat bed is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "clumpkit/core/error.hpp"
#include "clumpkit/rigs/heap_angle.hpp"

namespace clumpkit::rigs {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

class ConeAngle : public ::testing::TestWithParam<double> {};

TEST_P(ConeAngle, MeasuredWithinOneDegreeInBothWindows) {
  const double angle = GetParam() * kDeg;
  const Spheres s = synthetic_cone(0.06, angle, 0.0018, 7);
  const HeapAngle h = measure_heap_angle(s);
  EXPECT_NEAR(h.angle / kDeg, GetParam(), 1.0);
  EXPECT_NEAR(h.angle_left / kDeg, GetParam(), 1.0);
  EXPECT_NEAR(h.angle_right / kDeg, GetParam(), 1.0);
  EXPECT_NEAR(h.alt_angle / kDeg, GetParam(), 1.0);  // robust to the window
  EXPECT_NEAR(h.height_over_radius_angle / kDeg, GetParam(), 3.0);
  EXPECT_EQ(int(h.views.size()), 8);
  for (const auto& v : h.views) {
    EXPECT_NEAR(v.left.angle / kDeg, GetParam(), 2.5);
    EXPECT_NEAR(v.right.angle / kDeg, GetParam(), 2.5);
    EXPECT_LT(v.left.rms, 0.0018);  // residuals below a sphere radius: a straight flank
  }
  EXPECT_NEAR(h.axis.norm(), 0.0, 0.003);
}

INSTANTIATE_TEST_SUITE_P(Angles, ConeAngle, ::testing::Values(18.0, 25.0, 32.0, 40.0));

TEST(HeapAngle, SeedsAndWindowsAgree) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const Spheres s = synthetic_cone(0.05, 28.0 * kDeg, 0.002, seed);
    HeapAngleOptions o;
    for (auto [lo, hi] : {std::pair{0.2, 0.8}, {0.3, 0.7}, {0.15, 0.6}}) {
      o.window_low = lo, o.window_high = hi;
      EXPECT_NEAR(measure_heap_angle(s, o).angle / kDeg, 28.0, 1.0) << lo << "-" << hi;
    }
  }
}

TEST(HeapAngle, DetachedPillsAndSkirtAreIgnored) {
  Spheres s = synthetic_cone(0.05, 30.0 * kDeg, 0.0018, 4);
  const double clean = measure_heap_angle(s).angle;
  // A one-pill skirt on the plate out to 90 mm, and a few pills lying apart at mid height.
  for (int k = 0; k < 200; ++k) {
    const double a = 2 * std::numbers::pi * k / 200, r = 0.055 + 0.035 * (k % 7) / 7.0;
    s.push_back({Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0.0018), 0.0018});
  }
  s.push_back({Eigen::Vector3d(0.09, 0.0, 0.012), 0.0018});
  s.push_back({Eigen::Vector3d(-0.08, 0.02, 0.010), 0.0018});
  EXPECT_NEAR(measure_heap_angle(s).angle / kDeg, clean / kDeg, 0.5);
}

TEST(HeapAngle, FlatBedIsNotAHeap) {
  Spheres s;
  for (int i = -10; i <= 10; ++i)
    for (int j = -10; j <= 10; ++j)
      s.push_back({Eigen::Vector3d(0.003 * i, 0.003 * j, 0.0018), 0.0018});
  EXPECT_THROW(measure_heap_angle(s), NumericalError);
}

}  // namespace
}  // namespace clumpkit::rigs
