// Orientation of closed meshes body by body: the check that validate_mesh runs (bodies facing
// against their nesting) and the repair that load_mesh runs on request (orient_outward), on
// seeded random flips of meshes whose right orientation is known, on nested bodies, and on a
// one-sided surface.
#include "clumpkit/mesh_io/orientation.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <numbers>
#include <random>

#include "clumpkit/core/error.hpp"
#include "clumpkit/geometry/shape_spec.hpp"
#include "clumpkit/mesh_io/load_mesh.hpp"
#include "clumpkit/mesh_io/mesh_report.hpp"
#include "clumpkit/mesh_io/primitive_meshes.hpp"
#include "clumpkit/mesh_io/write_mesh.hpp"

namespace clumpkit {
namespace {

namespace fs = std::filesystem;

void flip_triangle(Eigen::Vector3i& t) {
  std::swap(t[1], t[2]);
}

// `b` appended to `a` (vertices renumbered), optionally shifted and turned inside out.
TriangleMesh join(TriangleMesh a, const TriangleMesh& b, const Eigen::Vector3d& shift,
                  bool inside_out) {
  const int base = static_cast<int>(a.vertices.size());
  for (const Eigen::Vector3d& v : b.vertices) a.vertices.push_back(v + shift);
  for (Eigen::Vector3i t : b.triangles) {
    t += Eigen::Vector3i::Constant(base);
    if (inside_out) flip_triangle(t);
    a.triangles.push_back(t);
  }
  return a;
}

// Each triangle the same cyclic order as in `want` (same vertices, same triangle order).
bool same_orientation(const TriangleMesh& got, const TriangleMesh& want) {
  if (got.triangles.size() != want.triangles.size()) return false;
  for (std::size_t f = 0; f < got.triangles.size(); ++f) {
    const Eigen::Vector3i& g = got.triangles[f];
    const Eigen::Vector3i& w = want.triangles[f];
    const bool rotation = (g == w) || (g == Eigen::Vector3i(w[1], w[2], w[0])) ||
                          (g == Eigen::Vector3i(w[2], w[0], w[1]));
    if (!rotation) return false;
  }
  return true;
}

// Reverses a random share of the triangles; returns how many.
std::size_t scramble(TriangleMesh& m, double share, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::bernoulli_distribution pick(share);
  std::size_t n = 0;
  for (Eigen::Vector3i& t : m.triangles)
    if (pick(rng)) flip_triangle(t), ++n;
  return n;
}

TEST(OrientOutward, UndoesRandomFlipsExactly) {
  const TriangleMesh shapes[] = {icosphere_mesh(0.003, 3), torus_mesh(0.02, 0.007, 48, 24),
                                 cylinder_mesh(0.006, 0.0054, 40, 3)};
  for (const TriangleMesh& good : shapes)
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      for (const double share : {0.1, 0.5, 0.9}) {
        TriangleMesh m = good;
        const std::size_t flipped = scramble(m, share, seed);
        ASSERT_GT(flipped, 0u);
        EXPECT_GT(validate_mesh(m, {false}).inconsistent_edges, 0u);
        const std::size_t reversed = orient_outward(m, "t");
        EXPECT_EQ(reversed, flipped);
        EXPECT_TRUE(same_orientation(m, good)) << "seed " << seed << " share " << share;
        const MeshReport r = validate_mesh(m);
        EXPECT_TRUE(r.closed_solid()) << r.defects();
      }
      // Inside out as a whole, and then some triangles flipped back: still outward at the end.
      TriangleMesh m = good;
      flip_orientation(m);
      scramble(m, 0.3, seed);
      orient_outward(m, "t");
      EXPECT_TRUE(same_orientation(m, good));
    }
}

TEST(OrientOutward, LeavesAConsistentOutwardMeshAlone) {
  TriangleMesh m = icosphere_mesh(1.0, 2);
  const TriangleMesh good = m;
  EXPECT_EQ(orient_outward(m, "t"), 0u);
  EXPECT_TRUE(same_orientation(m, good));
}

TEST(OrientOutward, NestedBodiesFaceOutwardByTheirNesting) {
  // A hollow ball (outer wall outward, cavity wall inward) with a free ball inside the cavity
  // (outward), beside a separate box (outward): the volumes are exact sums of the parts.
  const TriangleMesh outer = icosphere_mesh(2.0, 3), cavity = icosphere_mesh(1.0, 3);
  const TriangleMesh island = icosphere_mesh(0.4, 2), box = box_mesh(Eigen::Vector3d(1, 2, 3));
  TriangleMesh good = join(outer, cavity, Eigen::Vector3d::Zero(), true);
  good = join(good, island, Eigen::Vector3d::Zero(), false);
  good = join(good, box, Eigen::Vector3d(6, 0, 0), false);
  const double want = polyhedron_moments(outer).m0 - polyhedron_moments(cavity).m0 +
                      polyhedron_moments(island).m0 + 6.0;
  {
    const MeshReport r = validate_mesh(good);
    EXPECT_TRUE(r.closed_solid()) << r.defects();
    EXPECT_EQ(r.bodies, 4u);
    EXPECT_EQ(r.solids, 2u);  // the hollow ball (with its cavity and island) and the box
    EXPECT_NEAR(r.signed_volume, want, 1e-12 * want);
  }
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    TriangleMesh m = good;
    const std::size_t flipped = scramble(m, 0.4, seed);
    EXPECT_EQ(orient_outward(m, "t"), flipped);
    EXPECT_TRUE(same_orientation(m, good)) << "seed " << seed;
  }
  // Every body turned the wrong way round, one at a time: the repair turns it back.
  const std::size_t sizes[] = {outer.triangles.size(), cavity.triangles.size(),
                               island.triangles.size(), box.triangles.size()};
  std::size_t first = 0;
  for (const std::size_t n : sizes) {
    TriangleMesh m = good;
    for (std::size_t f = first; f < first + n; ++f) flip_triangle(m.triangles[f]);
    const MeshReport r = validate_mesh(m);
    EXPECT_EQ(r.inconsistent_edges, 0u);
    EXPECT_EQ(r.misoriented_bodies, 1u);
    EXPECT_FALSE(r.closed_solid());
    EXPECT_NE(r.defects().find("1 body inside out for its nesting"), std::string::npos)
        << r.defects();
    EXPECT_TRUE(r.orientation_repairable());
    EXPECT_EQ(orient_outward(m, "t"), n);
    EXPECT_TRUE(same_orientation(m, good));
    first += n;
  }
}

TEST(BodyOrientation, AWholeMeshInsideOutIsNotMisoriented) {
  // load_mesh flips a mesh whose total volume is negative; only bodies that disagree with the
  // rest count.
  TriangleMesh m = join(icosphere_mesh(1.0, 2), box_mesh(Eigen::Vector3d(1, 1, 1)),
                        Eigen::Vector3d(5, 0, 0), false);
  flip_orientation(m);
  const BodyOrientation b = body_orientation(m);
  EXPECT_EQ(b.bodies, 2u);
  EXPECT_EQ(b.misoriented, 0u);
  EXPECT_EQ(b.solids, 2u);
  EXPECT_EQ(body_orientation(icosphere_mesh(1.0, 1)).bodies, 1u);
  EXPECT_EQ(body_orientation(icosphere_mesh(1.0, 1)).solids, 1u);
  // A ball with a cavity is one solid of two bodies.
  const TriangleMesh hollow =
      join(icosphere_mesh(2.0, 2), icosphere_mesh(1.0, 2), Eigen::Vector3d::Zero(), true);
  EXPECT_EQ(body_orientation(hollow).bodies, 2u);
  EXPECT_EQ(body_orientation(hollow).solids, 1u);
}

TEST(OrientOutward, OneSidedAndOpenSurfacesAreRefused) {
  // The six-vertex triangulation of the real projective plane: closed, every edge shared by two
  // triangles, and one-sided.
  TriangleMesh rp2;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 6; ++i) rp2.vertices.emplace_back(u(rng), u(rng), u(rng));
  for (const auto& t :
       {Eigen::Vector3i(0, 1, 2), Eigen::Vector3i(0, 2, 3), Eigen::Vector3i(0, 3, 4),
        Eigen::Vector3i(0, 4, 5), Eigen::Vector3i(0, 5, 1), Eigen::Vector3i(1, 2, 4),
        Eigen::Vector3i(2, 3, 5), Eigen::Vector3i(3, 4, 1), Eigen::Vector3i(4, 5, 2),
        Eigen::Vector3i(5, 1, 3)})
    rp2.triangles.push_back(t);
  const MeshReport r = validate_mesh(rp2, {false});
  ASSERT_EQ(r.boundary_edges + r.nonmanifold_edges, 0u);
  ASSERT_GT(r.inconsistent_edges, 0u);
  try {
    orient_outward(rp2, "rp2.obj");
    ADD_FAILURE() << "a one-sided surface was oriented";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rp2.obj: the surface is not orientable"),
              std::string::npos)
        << e.what();
  }
  TriangleMesh open = box_mesh(Eigen::Vector3d(1, 1, 1));
  open.triangles.pop_back();
  EXPECT_THROW(orient_outward(open, "open.obj"), InputError);
  EXPECT_FALSE(validate_mesh(open).orientation_repairable());
}

class OrientationFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(CLUMPKIT_BINARY_DIR) / "test_tmp" /
           (std::string("orientation_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  fs::path dir_;
};

TEST_F(OrientationFiles, LoadMeshRefusesWithTheRemedyAndRepairsOnRequest) {
  const TriangleMesh good = torus_mesh(20, 7, 48, 24);  // millimetres
  TriangleMesh m = good;
  const std::size_t flipped = scramble(m, 0.15, 11);
  write_stl(m, dir_ / "scan.stl");  // binary STL: a triangle soup, welded on loading
  MeshLoadOptions opt;
  opt.scale = 1e-3;
  try {
    load_mesh(dir_ / "scan.stl", opt);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("scan.stl"), std::string::npos) << what;
    EXPECT_NE(what.find("edges with inconsistent orientation"), std::string::npos) << what;
    EXPECT_NE(what.find("--repair-orientation"), std::string::npos) << what;
  }
  opt.repair_orientation = true;
  MeshReport r;
  const TriangleMesh got = load_mesh(dir_ / "scan.stl", opt, &r);
  EXPECT_TRUE(r.closed_solid()) << r.defects();
  EXPECT_EQ(r.reoriented_faces, flipped);
  EXPECT_FALSE(r.flipped);
  const double want = polyhedron_moments(good).m0 * 1e-9;
  EXPECT_NEAR(polyhedron_moments(got).m0 / want, 1.0, 1e-6);  // STL stores floats
  // An open mesh is still refused, without the remedy (it would not help).
  TriangleMesh open = good;
  open.triangles.pop_back();
  write_stl(open, dir_ / "open.stl");
  try {
    load_mesh(dir_ / "open.stl", opt);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find("--repair-orientation"), std::string::npos) << e.what();
  }
}

TEST_F(OrientationFiles, ShapeFilesAskForTheRepair) {
  TriangleMesh m = icosphere_mesh(3.0, 3);
  scramble(m, 0.5, 2);
  write_obj(m, dir_ / "ball.obj");
  const std::string head = "[shape]\nkind = \"mesh\"\nfile = \"ball.obj\"\nunits = \"mm\"\n";
  const std::string tail = "[material]\ndensity = \"1380 kg/m^3\"\n";
  const ShapeSpec strict = parse_shape(head + tail, dir_ / "ball.toml");
  EXPECT_FALSE(strict.repair_orientation);
  EXPECT_THROW(load_shape_mesh(strict), InputError);
  const ShapeSpec lenient =
      parse_shape(head + "repair_orientation = true\n" + tail, dir_ / "ball.toml");
  EXPECT_TRUE(lenient.repair_orientation);
  MeshReport r;
  load_shape_mesh(lenient, &r);
  EXPECT_TRUE(r.closed_solid()) << r.defects();
  EXPECT_GT(r.reoriented_faces, 0u);
  const double want = polyhedron_moments(icosphere_mesh(3e-3, 3)).m0;
  EXPECT_NEAR(r.signed_volume / want, 1.0, 1e-6);  // assimp reads OBJ in single precision
}

}  // namespace
}  // namespace clumpkit
