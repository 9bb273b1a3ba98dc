// Hole repair on loading (MeshLoadOptions::repair_holes): seeded holes cut into closed meshes of
// known volume come back closed, outward and near their volume; the limits (a loop too long, a
// vertex where surfaces meet without an edge) are refused with their reason; without the option
// the error names it.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <set>

#include "clumpkit/core/error.hpp"
#include "clumpkit/mesh_io/load_mesh.hpp"
#include "clumpkit/mesh_io/mesh_report.hpp"
#include "clumpkit/mesh_io/primitive_meshes.hpp"
#include "clumpkit/mesh_io/write_mesh.hpp"

namespace clumpkit {
namespace {

namespace fs = std::filesystem;

class HoleFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::path(CLUMPKIT_BINARY_DIR) / "test_tmp" /
        (std::string("holes_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  fs::path dir_;
};

// Removes the triangles around `count` vertices picked at random, at least three edges apart
// (each leaves a hole bounded by the vertex's ring); returns the triangles removed.
std::size_t cut_holes(TriangleMesh& m, int count, std::uint64_t seed) {
  std::vector<std::set<int>> ring(m.vertices.size());
  for (const Eigen::Vector3i& t : m.triangles)
    for (int k = 0; k < 3; ++k) ring[t[k]].insert({t[(k + 1) % 3], t[(k + 2) % 3]});
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(m.vertices.size()) - 1);
  std::set<int> centres, blocked;
  while (static_cast<int>(centres.size()) < count) {
    const int v = pick(rng);
    if (blocked.count(v)) continue;
    centres.insert(v);
    // Block the 2-ring so that holes neither touch nor share a vertex.
    std::set<int> near = {v};
    for (int a : ring[v])
      for (int b : ring[a]) near.insert(b);
    for (int a : std::set<int>(near))
      for (int b : ring[a]) near.insert(b);
    blocked.insert(near.begin(), near.end());
  }
  const std::size_t before = m.triangles.size();
  std::erase_if(m.triangles, [&](const Eigen::Vector3i& t) {
    return centres.count(t[0]) || centres.count(t[1]) || centres.count(t[2]);
  });
  return before - m.triangles.size();
}

TEST_F(HoleFiles, SeededHolesAreClosedOutwardNearTheVolume) {
  const TriangleMesh shapes[] = {icosphere_mesh(3.0, 4), torus_mesh(20, 7, 64, 32)};  // mm
  for (std::size_t s = 0; s < 2; ++s)
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      SCOPED_TRACE(testing::Message() << "shape " << s << " seed " << seed);
      TriangleMesh m = shapes[s];
      const double want = polyhedron_moments(shapes[s]).m0 * 1e-9;
      const std::size_t removed = cut_holes(m, 5, seed);
      // Some triangles reversed as well (a scan's orientation is rarely consistent either).
      std::mt19937_64 rng(seed + 100);
      std::bernoulli_distribution flip(0.2);
      for (Eigen::Vector3i& t : m.triangles)
        if (flip(rng)) std::swap(t[1], t[2]);
      const fs::path path = dir_ / ("holey" + std::to_string(s) + ".obj");
      write_obj(m, path);
      MeshLoadOptions opt;
      opt.scale = 1e-3;
      try {
        load_mesh(path, opt);
        ADD_FAILURE() << "an open mesh was accepted";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--repair-holes"), std::string::npos) << e.what();
      }
      opt.repair_holes = true;
      MeshReport r;
      const TriangleMesh got = load_mesh(path, opt, &r);
      EXPECT_TRUE(r.closed_solid()) << r.defects();
      EXPECT_EQ(r.holes_filled, 5u);
      // A ring of k triangles leaves a k-gon, closed with k - 2 triangles.
      EXPECT_EQ(r.triangles_added, removed - 2 * 5);
      EXPECT_EQ(got.triangles.size(), m.triangles.size() + r.triangles_added);
      EXPECT_GT(r.signed_volume, 0.0);
      // Each lid replaces a low cap (or, on the torus's saddle, a low dimple).
      EXPECT_NEAR(r.signed_volume / want, 1.0, 5e-3);
      if (s == 0) {
        EXPECT_LT(r.signed_volume, want);  // convex: every cap is lost
      }
      EXPECT_GT(r.hole_area, 0.0);
      EXPECT_LT(r.hole_area, 0.02 * r.area);
    }
}

TEST_F(HoleFiles, LimitsAreRefusedWithTheirReason) {
  // A bowl: the lower half of an icosphere, one loop of many edges.
  TriangleMesh bowl = icosphere_mesh(1.0, 3);
  std::erase_if(bowl.triangles, [&](const Eigen::Vector3i& t) {
    return bowl.vertices[t[0]].z() + bowl.vertices[t[1]].z() + bowl.vertices[t[2]].z() > 0.0;
  });
  write_obj(bowl, dir_ / "bowl.obj");
  MeshLoadOptions opt;
  opt.repair_holes = true;
  MeshReport r;
  load_mesh(dir_ / "bowl.obj", opt, &r);
  EXPECT_EQ(r.holes_filled, 1u);
  EXPECT_GT(r.hole_area, 0.2 * r.area);  // the lid: what the caller should warn about
  opt.max_hole_edges = 10;
  try {
    load_mesh(dir_ / "bowl.obj", opt);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("too large to fill (at most 10)"), std::string::npos)
        << e.what();
  }
  // Two tetrahedra without their bottoms, touching at their apex only: CGAL needs a polygon mesh.
  TriangleMesh two;
  two.vertices = {{0, 0, 0}, {1, 0, -1}, {-1, 1, -1}, {-1, -1, -1},
                  {1, 0, 1}, {-1, 1, 1}, {-1, -1, 1}};
  two.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 1}, {0, 5, 4}, {0, 6, 5}, {0, 4, 6}};
  write_obj(two, dir_ / "two.obj");
  opt.max_hole_edges = 1000;
  try {
    load_mesh(dir_ / "two.obj", opt);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("two.obj: cannot fill its holes"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace clumpkit
