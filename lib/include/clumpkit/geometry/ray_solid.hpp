#pragma once
/// A solid that reports where an axis-parallel line lies inside it. Implemented analytically for
/// spheres, sphere unions and cylinders (geometry), and with Embree for meshes (raycast).
#include <Eigen/Geometry>

#include "clumpkit/geometry/intervals.hpp"

namespace clumpkit {

class RaySolid {
 public:
  virtual ~RaySolid() = default;
  /// Axis-aligned bounds in metres.
  virtual Eigen::AlignedBox3d bounds() const = 0;
  /// Appends to `out` (cleared first) the normalised intervals of t where origin + t * e_axis lies
  /// inside the solid. `origin[axis]` is ignored (treated as 0): t is the coordinate along `axis`.
  /// Must be thread-safe: called concurrently from several threads.
  virtual void intervals(const Eigen::Vector3d& origin, int axis, IntervalList& out) const = 0;
};

}  // namespace clumpkit
