#include "clumpkit/geometry/sphere_union.hpp"

#include <algorithm>
#include <cmath>

namespace clumpkit {

SphereUnion::SphereUnion(Spheres spheres) : spheres_(std::move(spheres)) {
  bounds_ = clumpkit::bounds(spheres_);
  for (const Sphere& s : spheres_) rmax_ = std::max(rmax_, s.radius);
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3;
    auto& ord = order_[axis];
    ord.resize(spheres_.size());
    for (size_t i = 0; i < ord.size(); ++i) ord[i] = static_cast<int>(i);
    std::sort(ord.begin(), ord.end(), [&](int a, int b) {
      return spheres_[a].center[u] - spheres_[a].radius <
             spheres_[b].center[u] - spheres_[b].radius;
    });
    lo_[axis].resize(ord.size());
    for (size_t i = 0; i < ord.size(); ++i)
      lo_[axis][i] = spheres_[ord[i]].center[u] - spheres_[ord[i]].radius;
  }
}

void SphereUnion::intervals(const Eigen::Vector3d& origin, int axis, IntervalList& out) const {
  out.clear();
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const double pu = origin[u], pv = origin[v];
  // Spheres whose u-extent starts at or below pu; those starting beyond cannot be hit.
  const auto& lo = lo_[axis];
  const size_t end = static_cast<size_t>(std::upper_bound(lo.begin(), lo.end(), pu) - lo.begin());
  for (size_t k = 0; k < end; ++k) {
    const Sphere& s = spheres_[order_[axis][k]];
    const double du = pu - s.center[u];
    if (du > s.radius) continue;
    const double dv = pv - s.center[v];
    const double h2 = s.radius * s.radius - du * du - dv * dv;
    if (h2 <= 0.0) continue;
    const double h = std::sqrt(h2);
    out.push_back({s.center[axis] - h, s.center[axis] + h});
  }
  merge_intervals(out);
}

}  // namespace clumpkit
