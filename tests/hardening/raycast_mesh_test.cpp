// A small raycast workload for the sanitizer builds (labels raycast;sanitize): a mesh target
// (assimp → mesh_io → Embree-backed MeshSolid) measured against a sphere union, and the
// documented refusals of bad clumps. The raycast module's own suite is not labelled `sanitize`.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "clumpkit/core/error.hpp"
#include "clumpkit/mesh_io/load_mesh.hpp"
#include "clumpkit/raycast/shape_error.hpp"
#include "clumpkit/raycast/target_shape.hpp"

namespace clumpkit {
namespace {

const std::filesystem::path kCube = std::filesystem::path(CLUMPKIT_SOURCE_DIR) / "meshes/cube.stl";

ShapeErrorOptions small() {
  ShapeErrorOptions o;
  o.sampling.rays = 20000;
  o.surface_samples = 2000;
  return o;
}

TEST(RaycastUnderSanitizers, MeshTargetAgainstASphere) {
  const TriangleMesh m = load_mesh(kCube);
  const Eigen::AlignedBox3d box = mesh_bounds(m);
  const double half = 0.5 * box.sizes().minCoeff();
  const TargetShape t = target_from_mesh(kCube);
  const Spheres one = {{box.center(), half}};
  const ShapeError e = shape_error(*t.solid, one, small());
  const double cube = box.sizes().prod();
  EXPECT_NEAR(e.shape.volume, cube, 0.02 * cube);
  // The inscribed sphere fills pi/6 of the cube.
  EXPECT_NEAR(e.volume_rel_error.value, std::acos(-1.0) / 6.0 - 1.0, 0.03);
  EXPECT_TRUE(std::isfinite(e.sym_diff_rel.value));
}

TEST(RaycastUnderSanitizers, BadSpheresAreInputErrors) {
  const TargetShape t = target_from_mesh(kCube);
  EXPECT_THROW(shape_error(*t.solid, {}, small()), InputError);
  EXPECT_THROW(shape_error(*t.solid, {{Eigen::Vector3d(NAN, 0, 0), 1.0}}, small()), InputError);
  EXPECT_THROW(shape_error(*t.solid, {{Eigen::Vector3d::Zero(), -1.0}}, small()), InputError);
}

}  // namespace
}  // namespace clumpkit
