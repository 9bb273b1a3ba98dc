#include "clumpkit/geometry/sphere.hpp"

#include <cmath>
#include <string>

#include "clumpkit/core/error.hpp"

namespace clumpkit {

Eigen::AlignedBox3d bounds(const Spheres& spheres) {
  Eigen::AlignedBox3d box;
  for (const Sphere& s : spheres) {
    box.extend(s.center - Eigen::Vector3d::Constant(s.radius));
    box.extend(s.center + Eigen::Vector3d::Constant(s.radius));
  }
  return box;
}

void validate_spheres(const Spheres& spheres, const std::string& where) {
  if (spheres.empty()) throw InputError(where, "spheres", "the clump has no spheres");
  for (size_t i = 0; i < spheres.size(); ++i) {
    const Sphere& s = spheres[i];
    const std::string field = "spheres[" + std::to_string(i) + "]";
    if (!s.center.allFinite() || !std::isfinite(s.radius))
      throw InputError(where, field, "coordinate or radius is not finite");
    if (s.radius <= 0.0)
      throw InputError(where, field, "radius " + std::to_string(s.radius) + " m is not positive");
  }
}

}  // namespace clumpkit
