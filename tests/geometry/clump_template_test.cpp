#include "clumpkit/geometry/clump_template.hpp"

#include <gtest/gtest.h>

#include <random>

#include "clumpkit/core/error.hpp"

using namespace clumpkit;

// Random asymmetric clumps: the template frame is centroid-principal, and mapping back with the
// recorded frame gives the source spheres.
TEST(ClumpTemplate, FrameIsCentroidPrincipalAndMapsBack) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1e-3, 1e-3), ur(0.3e-3, 0.9e-3);
  for (int trial = 0; trial < 10; ++trial) {
    Spheres src;
    for (int i = 0; i < 5; ++i) src.push_back({Eigen::Vector3d(u(rng), u(rng), u(rng)), ur(rng)});
    RaySamplingOptions o;
    o.rays = 300000;
    o.seed = trial + 1;
    const ClumpTemplate t = make_clump_template(src, 1000.0, o);
    const double size = bounds(src).diagonal().norm();
    EXPECT_LT(t.mass.center_of_mass.norm(), 1e-9 * size + 1e-15);
    const Eigen::Matrix3d& i = t.mass.inertia_tensor;
    EXPECT_LT(std::abs(i(0, 1)) + std::abs(i(0, 2)) + std::abs(i(1, 2)), 1e-9 * i.trace());
    EXPECT_NEAR(t.rotation.determinant(), 1.0, 1e-12);
    const Spheres back = t.spheres_in_source_frame();
    for (size_t k = 0; k < src.size(); ++k) {
      EXPECT_NEAR((back[k].center - src[k].center).norm(), 0.0, 1e-15);
      EXPECT_EQ(back[k].radius, src[k].radius);
    }
  }
}

TEST(ClumpTemplate, JsonRoundTrip) {
  const ClumpTemplate t = make_clump_template(
      {{Eigen::Vector3d(0, 0, 0), 1e-3}, {Eigen::Vector3d(1e-3, 0.2e-3, 0), 0.7e-3}}, 1380.0);
  const ClumpTemplate r = clump_from_json(nlohmann::json::parse(to_json(t).dump()), "mem");
  ASSERT_EQ(r.spheres.size(), t.spheres.size());
  for (size_t k = 0; k < t.spheres.size(); ++k) {
    EXPECT_EQ(r.spheres[k].center, t.spheres[k].center);
    EXPECT_EQ(r.spheres[k].radius, t.spheres[k].radius);
  }
  EXPECT_EQ(r.mass.mass, t.mass.mass);
  EXPECT_EQ(r.mass.inertia_tensor, t.mass.inertia_tensor);
  EXPECT_EQ(r.rotation, t.rotation);
  EXPECT_EQ(r.translation, t.translation);
}

TEST(ClumpTemplate, MalformedJsonNamesTheField) {
  auto j = to_json(make_clump_template({{Eigen::Vector3d::Zero(), 1e-3}}, 1000.0));
  auto bad = j;
  bad["spheres"][0][3] = -1.0;
  try {
    clump_from_json(bad, "c.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("c.json: spheres[0]: radius"), std::string::npos);
  }
  bad = j;
  bad["spheres"] = nlohmann::json::array();
  EXPECT_THROW(clump_from_json(bad, "c.json"), InputError);
  bad = j;
  bad["mass_properties"].erase("mass");
  try {
    clump_from_json(bad, "c.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mass_properties.mass: missing"), std::string::npos);
  }
}
