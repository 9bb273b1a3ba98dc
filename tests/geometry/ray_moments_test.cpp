#include "clumpkit/geometry/ray_moments.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "clumpkit/geometry/cylinder.hpp"
#include "clumpkit/geometry/mass_properties.hpp"
#include "clumpkit/geometry/sphere_union.hpp"

using namespace clumpkit;
constexpr double kPi = std::numbers::pi;

namespace {
double sphere_volume(double r) {
  return 4.0 / 3.0 * kPi * r * r * r;
}
// Volume of the lens where two spheres (radii r1, r2, centre distance d) overlap.
double lens_volume(double r1, double r2, double d) {
  if (d >= r1 + r2) return 0.0;
  if (d <= std::abs(r1 - r2)) return sphere_volume(std::min(r1, r2));
  return kPi * std::pow(r1 + r2 - d, 2) *
         (d * d + 2 * d * r2 - 3 * r2 * r2 + 2 * d * r1 + 6 * r1 * r2 - 3 * r1 * r1) / (12 * d);
}
}  // namespace

TEST(RayMoments, SphereMatchesClosedForm) {
  const double r = 1.3e-3;
  SphereUnion u({{Eigen::Vector3d(0.2e-3, -0.1e-3, 0.4e-3), r}});
  MassPropertiesCI ci;
  MassProperties mp = mass_properties(integrate_solid(u, {}), 1000.0, &ci);
  const MassProperties ref = sphere_mass_properties(r, 1000.0);
  EXPECT_NEAR(mp.volume / ref.volume, 1.0, 1e-3);
  EXPECT_LE(std::abs(mp.volume - ref.volume), std::max(3.0 * ci.volume, 1e-6 * ref.volume));
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(mp.principal_moments[k] / ref.principal_moments[k], 1.0, 1e-3);
  EXPECT_NEAR((mp.center_of_mass - Eigen::Vector3d(0.2e-3, -0.1e-3, 0.4e-3)).norm(), 0.0, 1e-7);
}

// Seeded property test over random two-sphere unions (lens by inclusion-exclusion).
TEST(RayMoments, TwoSphereUnionsMatchInclusionExclusion) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> ur(0.5, 2.0), ud(0.0, 3.5);
  int covered = 0;
  const int trials = 40;
  for (int t = 0; t < trials; ++t) {
    const double r1 = ur(rng), r2 = ur(rng), d = ud(rng);
    const Eigen::Vector3d dir = Eigen::Vector3d::Random().normalized();
    SphereUnion u({{Eigen::Vector3d::Zero(), r1}, {d * dir, r2}});
    RaySamplingOptions o;
    o.rays = 300000;
    o.seed = 100 + t;
    auto samples = integrate_solid(u, o);
    std::vector<double> vols;
    for (const auto& s : samples) vols.push_back(s.m0);
    const Estimate e = estimate(vols);
    const double truth = sphere_volume(r1) + sphere_volume(r2) - lens_volume(r1, r2, d);
    EXPECT_NEAR(e.value / truth, 1.0, 2e-3) << "r1 " << r1 << " r2 " << r2 << " d " << d;
    if (std::abs(e.value - truth) <= e.ci95) ++covered;
  }
  // A 95 % interval should cover the truth in most trials (binomial: >= 30 of 40 is p > 0.999).
  EXPECT_GE(covered, 30);
}

TEST(RayMoments, CylinderMatchesClosedFormToPointOnePercent) {
  const Cylinder c(6.0e-3, 5.4e-3);
  MassPropertiesCI ci;
  MassProperties mp = mass_properties(integrate_solid(c, {}), 1380.0, &ci);
  const MassProperties ref = cylinder_mass_properties(3.0e-3, 5.4e-3, 1380.0);
  EXPECT_NEAR(mp.volume / ref.volume, 1.0, 1e-3);
  EXPECT_LE(std::abs(mp.volume - ref.volume), 3.0 * ci.volume + 1e-12 * ref.volume);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(mp.principal_moments[k] / ref.principal_moments[k], 1.0, 1e-3) << k;
  // The frame of a symmetric solid stays on its coordinate axes.
  EXPECT_NEAR(std::abs(mp.principal_axes.col(0).dot(ref.principal_axes.col(0))), 1.0, 1e-9);
}

TEST(RayMoments, BitIdenticalForOneAndTwoThreads) {
  std::mt19937_64 rng(3);
  Spheres s;
  for (int i = 0; i < 20; ++i)
    s.push_back({Eigen::Vector3d::Random(), 0.3 + 0.5 * (rng() % 100) / 100.0});
  SphereUnion u(s);
  RaySamplingOptions o;
  o.rays = 200000;
  o.threads = 1;
  auto a = integrate_solid(u, o);
  o.threads = 2;
  auto b = integrate_solid(u, o);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].m0, b[i].m0);
    EXPECT_EQ(a[i].m1, b[i].m1);
    EXPECT_EQ(a[i].m2, b[i].m2);
  }
}
