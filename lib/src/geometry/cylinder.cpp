#include "clumpkit/geometry/cylinder.hpp"

#include <algorithm>
#include <cmath>

namespace clumpkit {

Eigen::AlignedBox3d Cylinder::bounds() const {
  return {Eigen::Vector3d(-r_, -r_, -0.5 * h_), Eigen::Vector3d(r_, r_, 0.5 * h_)};
}

void Cylinder::intervals(const Eigen::Vector3d& o, int axis, IntervalList& out) const {
  out.clear();
  if (axis == 2) {
    if (o.x() * o.x() + o.y() * o.y() < r_ * r_) out.push_back({-0.5 * h_, 0.5 * h_});
    return;
  }
  const double z = o.z();
  if (std::abs(z) >= 0.5 * h_) return;
  const double w = axis == 0 ? o.y() : o.x();  // transverse coordinate in the xy plane
  const double c2 = r_ * r_ - w * w;
  if (c2 <= 0.0) return;
  const double c = std::sqrt(c2);
  out.push_back({-c, c});
}

double Cylinder::signed_distance(const Eigen::Vector3d& p) const {
  const double dr = std::hypot(p.x(), p.y()) - r_;
  const double dz = std::abs(p.z()) - 0.5 * h_;
  const double outside = std::hypot(std::max(dr, 0.0), std::max(dz, 0.0));
  return outside + std::min(std::max(dr, dz), 0.0);
}

}  // namespace clumpkit
