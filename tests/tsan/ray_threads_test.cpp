// The ray integrator under several threads: a TSan workload (small, TSan is 5-15x slower) that
// also asserts the documented determinism: the same seed gives bit-identical moments whatever the
// thread count, for a single solid and for the multi-channel integration.
#include <gtest/gtest.h>

#include <random>

#include "clumpkit/geometry/clump_template.hpp"
#include "clumpkit/geometry/ray_moments.hpp"
#include "clumpkit/geometry/sphere_union.hpp"

namespace clumpkit {
namespace {

Spheres random_spheres(unsigned seed, int n) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(-1e-3, 1e-3), rad(0.3e-3, 0.8e-3);
  Spheres s;
  for (int i = 0; i < n; ++i)
    s.push_back({Eigen::Vector3d(pos(rng), pos(rng), pos(rng)), rad(rng)});
  return s;
}

void expect_identical(const std::vector<Moments>& a, const std::vector<Moments>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].m0, b[i].m0);
    EXPECT_EQ(a[i].m1, b[i].m1);
    EXPECT_EQ(a[i].m2, b[i].m2);
  }
}

TEST(RayThreads, SolidMomentsIndependentOfThreadCount) {
  const SphereUnion u(random_spheres(7, 12));
  RaySamplingOptions o;
  o.rays = 24000;
  o.seed = 5;
  o.threads = 1;
  const auto one = integrate_solid(u, o);
  for (int threads : {2, 3, 4}) {
    o.threads = threads;
    expect_identical(one, integrate_solid(u, o));
  }
}

TEST(RayThreads, ChannelsIndependentOfThreadCount) {
  const SphereUnion a(random_spheres(1, 6)), b(random_spheres(2, 6));
  Eigen::AlignedBox3d box = a.bounds();
  box.extend(b.bounds());
  const RayChannels channels = [&](const Eigen::Vector3d& origin, int axis,
                                   std::vector<IntervalList>& out) {
    a.intervals(origin, axis, out[0]);
    b.intervals(origin, axis, out[1]);
  };
  RaySamplingOptions o;
  o.rays = 24000;
  o.threads = 1;
  const auto one = integrate_rays(box, 2, channels, o);
  o.threads = 4;
  const auto four = integrate_rays(box, 2, channels, o);
  ASSERT_EQ(one.size(), 2u);
  for (int c = 0; c < 2; ++c) expect_identical(one[c], four[c]);
}

TEST(RayThreads, ClumpTemplateIndependentOfThreadCount) {
  const Spheres s = random_spheres(3, 8);
  RaySamplingOptions o;
  o.rays = 24000;
  o.threads = 1;
  const ClumpTemplate one = make_clump_template(s, 1380.0, o);
  o.threads = 2;
  const ClumpTemplate two = make_clump_template(s, 1380.0, o);
  EXPECT_EQ(to_json(one).dump(), to_json(two).dump());
}

}  // namespace
}  // namespace clumpkit
