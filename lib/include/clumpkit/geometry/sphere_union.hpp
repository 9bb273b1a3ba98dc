#pragma once
#include "clumpkit/geometry/ray_solid.hpp"
#include "clumpkit/geometry/sphere.hpp"

namespace clumpkit {

/// The union of a set of (possibly overlapping) spheres, intersected exactly by rays.
class SphereUnion final : public RaySolid {
 public:
  explicit SphereUnion(Spheres spheres);
  Eigen::AlignedBox3d bounds() const override { return bounds_; }
  void intervals(const Eigen::Vector3d& origin, int axis, IntervalList& out) const override;
  const Spheres& spheres() const { return spheres_; }

 private:
  Spheres spheres_;
  Eigen::AlignedBox3d bounds_;
  // Per axis, sphere indices sorted by the lower bound of one transverse coordinate, for a cheap
  // prefilter when many spheres are present.
  std::vector<int> order_[3];
  std::vector<double> lo_[3];
  double rmax_ = 0.0;
};

}  // namespace clumpkit
