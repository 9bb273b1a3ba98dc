#pragma once
#include <Eigen/Core>
#include <vector>

#include "clumpkit/geometry/ray_moments.hpp"

namespace clumpkit {

/// Mass properties of a homogeneous solid, SI units, in the frame the moments were taken in.
struct MassProperties {
  double density = 0.0;                                      ///< kg/m^3
  double volume = 0.0;                                       ///< m^3
  double mass = 0.0;                                         ///< kg
  Eigen::Vector3d center_of_mass = Eigen::Vector3d::Zero();  ///< m
  Eigen::Matrix3d inertia_tensor = Eigen::Matrix3d::Zero();  ///< kg m^2, about the centre of mass
  Eigen::Vector3d principal_moments = Eigen::Vector3d::Zero();  ///< kg m^2, ascending
  /// Columns are the principal axes (right-handed), matching principal_moments.
  Eigen::Matrix3d principal_axes = Eigen::Matrix3d::Identity();
};

/// Sampled uncertainties (95 % half-widths) of the figures above.
struct MassPropertiesCI {
  double volume = 0.0;
  Eigen::Vector3d center_of_mass = Eigen::Vector3d::Zero();
  Eigen::Vector3d principal_moments = Eigen::Vector3d::Zero();
};

/// Mass properties from raw moments. Principal axes are chosen stably: axes within `snap_deg` of
/// a coordinate axis snap to it, and for (near-)equal moments (relative gap below `degenerate`)
/// the frame keeps the coordinate axes, so a symmetric shape keeps its natural frame.
MassProperties mass_properties(const Moments& m, double density, double snap_deg = 0.5,
                               double degenerate = 1e-3);

/// Mass properties and their 95 % intervals from replicate samples.
MassProperties mass_properties(const std::vector<Moments>& samples, double density,
                               MassPropertiesCI* ci);

/// Closed forms used by tests and by exact shapes.
MassProperties sphere_mass_properties(double radius, double density);
MassProperties cylinder_mass_properties(double radius, double height, double density);  // axis z
MassProperties box_mass_properties(const Eigen::Vector3d& sizes, double density);

}  // namespace clumpkit
