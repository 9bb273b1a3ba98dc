#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace clumpkit {

/// A sphere: centre in metres (in whatever frame the owner states) and radius in metres.
struct Sphere {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

using Spheres = std::vector<Sphere>;

/// Axis-aligned bounds of a set of spheres.
Eigen::AlignedBox3d bounds(const Spheres& spheres);

/// Throws InputError(where, "spheres[i]") for an empty list, a non-finite coordinate or a radius
/// that is not strictly positive.
void validate_spheres(const Spheres& spheres, const std::string& where);

}  // namespace clumpkit
