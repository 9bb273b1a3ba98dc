#pragma once
/// Test shapes for the fill methods: each is an analytic solid (exact ray intervals along
/// axis-parallel lines, a signed distance, an exact volume) and can be tessellated into a closed,
/// outward-oriented triangle mesh. The set (issue 4): pills A, B, C with sharp and chamfered
/// edges, an ellipsoid 2:1:1, a capsule, a cube, a superellipsoid seed-like grain, a seeded random
/// convex rock, a torus and an L-shaped bracket. Lengths in metres.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "clumpkit/geometry/ray_solid.hpp"

namespace clumpkit {

/// An indexed triangle mesh; triangles are counter-clockwise seen from outside.
struct TessellatedMesh {
  std::vector<Eigen::Vector3d> vertices;      ///< m
  std::vector<std::array<int, 3>> triangles;  ///< vertex indices
  /// Signed enclosed volume (divergence theorem), m^3; positive for outward orientation.
  double signed_volume() const;
  /// Every edge used exactly twice, once in each direction (closed, consistently oriented).
  bool is_closed_and_oriented() const;
};

/// ASCII STL / Wavefront OBJ text of a mesh; coordinates multiplied by `scale` (1000: mm).
std::string to_ascii_stl(const TessellatedMesh& mesh, const std::string& name, double scale);
std::string to_obj(const TessellatedMesh& mesh, const std::string& name, double scale);

/// A solid known in closed form.
class AnalyticSolid : public RaySolid {
 public:
  /// Signed distance to the surface (negative inside), m. Exact when has_exact_distance(),
  /// otherwise only its sign is reliable.
  virtual double signed_distance(const Eigen::Vector3d& p) const = 0;
  virtual bool has_exact_distance() const { return true; }
  /// Exact volume, m^3.
  virtual double volume() const = 0;
  /// A closed, outward-oriented mesh with roughly `triangles` triangles (flat-faced solids use
  /// their own faces and ignore it).
  virtual TessellatedMesh tessellate(int triangles) const = 0;
};

/// A cylinder (axis z, centred) whose two circular edges are cut by 45-degree chamfers of leg
/// `chamfer` (0: sharp edges).
class ChamferedCylinder final : public AnalyticSolid {
 public:
  ChamferedCylinder(double diameter, double height, double chamfer);
  Eigen::AlignedBox3d bounds() const override;
  void intervals(const Eigen::Vector3d& origin, int axis, IntervalList& out) const override;
  double signed_distance(const Eigen::Vector3d& p) const override;
  double volume() const override;
  TessellatedMesh tessellate(int triangles) const override;

 private:
  double r_, h_, c_;
};

/// Ellipsoid with semi-axes a, b, c along x, y, z. The distance is exact for spheroids (a == b).
class Ellipsoid final : public AnalyticSolid {
 public:
  Ellipsoid(double a, double b, double c);
  Eigen::AlignedBox3d bounds() const override;
  void intervals(const Eigen::Vector3d& origin, int axis, IntervalList& out) const override;
  double signed_distance(const Eigen::Vector3d& p) const override;
  bool has_exact_distance() const override { return a_ == b_; }
  double volume() const override;
  TessellatedMesh tessellate(int triangles) const override;

 private:
  double a_, b_, c_;
};

/// Capsule: a cylinder of radius r and straight length l along z, capped by hemispheres.
class Capsule final : public AnalyticSolid {
 public:
  Capsule(double radius, double length);
  Eigen::AlignedBox3d bounds() const override;
  void intervals(const Eigen::Vector3d& origin, int axis, IntervalList& out) const override;
  double signed_distance(const Eigen::Vector3d& p) const override;
  double volume() const override;
  TessellatedMesh tessellate(int triangles) const override;

 private:
  double r_, l_;
};

/// Torus about z: tube of radius r on a circle of radius R > r.
class Torus final : public AnalyticSolid {
 public:
  Torus(double major_radius, double minor_radius);
  Eigen::AlignedBox3d bounds() const override;
  void intervals(const Eigen::Vector3d& origin, int axis, IntervalList& out) const override;
  double signed_distance(const Eigen::Vector3d& p) const override;
  double volume() const override;
  TessellatedMesh tessellate(int triangles) const override;

 private:
  double R_, r_;
};

/// Superellipsoid (|x/a|^(2/e2) + |y/b|^(2/e2))^(e2/e1) + |z/c|^(2/e1) <= 1. Only the sign of its
/// distance is reliable; volume by numerical quadrature.
class Superellipsoid final : public AnalyticSolid {
 public:
  Superellipsoid(const Eigen::Vector3d& semi_axes, double e1, double e2);
  Eigen::AlignedBox3d bounds() const override;
  void intervals(const Eigen::Vector3d& origin, int axis, IntervalList& out) const override;
  double signed_distance(const Eigen::Vector3d& p) const override;
  bool has_exact_distance() const override { return false; }
  double volume() const override { return volume_; }
  TessellatedMesh tessellate(int triangles) const override;

 private:
  double inside_function(const Eigen::Vector3d& p) const;
  Eigen::Vector3d s_;
  double e1_, e2_, volume_ = 0.0;
};

/// Convex polytope {x : n_i . x <= d_i} (unit normals); must be bounded.
class ConvexPolytope final : public AnalyticSolid {
 public:
  struct Plane {
    Eigen::Vector3d normal;
    double offset;
  };
  explicit ConvexPolytope(std::vector<Plane> planes);
  Eigen::AlignedBox3d bounds() const override { return bounds_; }
  void intervals(const Eigen::Vector3d& origin, int axis, IntervalList& out) const override;
  /// Exact inside; outside a lower bound of the distance (the sign is exact).
  double signed_distance(const Eigen::Vector3d& p) const override;
  double volume() const override { return volume_; }
  TessellatedMesh tessellate(int triangles) const override { return mesh_; }
  const std::vector<Plane>& planes() const { return planes_; }

 private:
  std::vector<Plane> planes_;
  TessellatedMesh mesh_;
  Eigen::AlignedBox3d bounds_;
  double volume_ = 0.0;
};

/// A simple polygon in the xz plane (counter-clockwise, seen from +y... i.e. in (x, z)) extruded
/// over y in [-w/2, w/2]. Used for the L-shaped bracket (non-convex).
class ExtrudedPolygon final : public AnalyticSolid {
 public:
  /// `triangulation` indexes `polygon` (counter-clockwise in (x, z)).
  ExtrudedPolygon(std::vector<Eigen::Vector2d> polygon, double width,
                  std::vector<std::array<int, 3>> triangulation);
  Eigen::AlignedBox3d bounds() const override;
  void intervals(const Eigen::Vector3d& origin, int axis, IntervalList& out) const override;
  double signed_distance(const Eigen::Vector3d& p) const override;
  double volume() const override;
  TessellatedMesh tessellate(int triangles) const override;

 private:
  bool inside_2d(const Eigen::Vector2d& q) const;
  std::vector<Eigen::Vector2d> poly_;
  double w_;
  std::vector<std::array<int, 3>> tri_;
};

/// Names of the bundled test shapes, in table order.
const std::vector<std::string>& test_shape_names();
/// Whether `name` is one of test_shape_names().
bool is_test_shape(const std::string& name);
/// One-line description (dimensions) of a test shape.
std::string test_shape_description(const std::string& name);
/// Builds a test shape; `seed` only matters for "rock". Throws InputError (field "SHAPE") listing
/// the names for an unknown one.
std::shared_ptr<const AnalyticSolid> make_test_shape(const std::string& name,
                                                     std::uint64_t seed = 1);

}  // namespace clumpkit
