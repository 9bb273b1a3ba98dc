#pragma once
#include "clumpkit/geometry/ray_solid.hpp"

namespace clumpkit {

/// A solid right circular cylinder, axis z, centred at the origin; exact ray intervals.
class Cylinder final : public RaySolid {
 public:
  Cylinder(double diameter, double height) : r_(0.5 * diameter), h_(height) {}
  double diameter() const { return 2.0 * r_; }
  double height() const { return h_; }
  Eigen::AlignedBox3d bounds() const override;
  void intervals(const Eigen::Vector3d& origin, int axis, IntervalList& out) const override;
  /// Signed distance to the surface (negative inside), metres.
  double signed_distance(const Eigen::Vector3d& p) const;

 private:
  double r_, h_;
};

}  // namespace clumpkit
