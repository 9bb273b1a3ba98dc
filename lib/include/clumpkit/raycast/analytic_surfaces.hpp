#pragma once
/// Analytic solids with exact surfaces: the paper's cylinder and the clump's sphere union.
#include "clumpkit/geometry/cylinder.hpp"
#include "clumpkit/geometry/sphere_union.hpp"
#include "clumpkit/raycast/surface_solid.hpp"

namespace clumpkit {

/// The solid cylinder of geometry/cylinder.hpp (axis z, centred), with exact distance.
class CylinderSurface final : public SurfaceSolid {
 public:
  CylinderSurface(double diameter, double height) : cyl_(diameter, height) {}
  Eigen::AlignedBox3d bounds() const override { return cyl_.bounds(); }
  void intervals(const Eigen::Vector3d& o, int axis, IntervalList& out) const override {
    cyl_.intervals(o, axis, out);
  }
  double surface_distance(const Eigen::Vector3d& p) const override;
  std::vector<Eigen::Vector3d> sample_surface(std::size_t n, std::uint64_t seed) const override;
  const Cylinder& cylinder() const { return cyl_; }

 private:
  Cylinder cyl_;
};

/// The boundary of a union of spheres: the parts of each sphere not inside another. Distances
/// are exact: outside the union, min(|p - c| - r); inside, the nearest of the candidate closest
/// points on sphere patches, on intersection circles and at triple points that lie on the
/// boundary.
class SphereUnionSurface final : public SurfaceSolid {
 public:
  /// Throws InputError("clump", "spheres[i]") for an empty list or a bad sphere.
  explicit SphereUnionSurface(Spheres spheres);
  Eigen::AlignedBox3d bounds() const override { return union_.bounds(); }
  void intervals(const Eigen::Vector3d& o, int axis, IntervalList& out) const override {
    union_.intervals(o, axis, out);
  }
  double surface_distance(const Eigen::Vector3d& p) const override;
  /// Area-uniform points on the union's boundary (rejection from the spheres' surfaces).
  std::vector<Eigen::Vector3d> sample_surface(std::size_t n, std::uint64_t seed) const override;
  /// As sample_surface, but only on the outer boundary: a point is dropped as the wall of an
  /// enclosed void when none of 27 rays from it (its normal, and the 26 axis and diagonal
  /// directions pointing away from its sphere) escapes the union. A heuristic: a deep, narrow
  /// pocket of the outer surface can be taken for a void. `dropped` counts the dropped points.
  std::vector<Eigen::Vector3d> sample_outer_surface(std::size_t n, std::uint64_t seed,
                                                    std::size_t* dropped = nullptr) const;
  const Spheres& spheres() const { return union_.spheres(); }

 private:
  bool on_boundary(const Eigen::Vector3d& q, int skip_a, int skip_b, int skip_c) const;
  bool escapes(const Eigen::Vector3d& q, int sphere) const;
  std::vector<Eigen::Vector3d> sample(std::size_t n, std::uint64_t seed, bool outer,
                                      std::size_t* dropped) const;

  SphereUnion union_;
  struct Circle {
    Eigen::Vector3d center, normal;
    double radius;
    int i, j;
  };
  std::vector<Circle> circles_;
  std::vector<Eigen::Vector3d> vertices_;  // triple points on the boundary
  double tol_ = 0.0;
};

}  // namespace clumpkit
