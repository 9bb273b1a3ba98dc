#pragma once
/// The clump template: spheres in the clump's centroid-principal frame, the sphere union's mass
/// properties, and the transform back to the source shape. File format "clumpkit-clump/1" (JSON).
#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "clumpkit/geometry/mass_properties.hpp"
#include "clumpkit/geometry/sphere.hpp"

namespace clumpkit {

inline constexpr const char* kClumpFormat = "clumpkit-clump/1";

struct ClumpTemplate {
  std::string name;
  /// Spheres in the centroid-principal frame, metres.
  Spheres spheres;
  /// Of the sphere union (never the sum of spheres), in the template frame: centre of mass ~0,
  /// inertia tensor ~diagonal.
  MassProperties mass;
  MassPropertiesCI mass_ci;
  /// How `mass` was obtained (method, rays, seed) and the mass basis ("sphere_union", ...).
  nlohmann::json mass_method = nlohmann::json::object();
  /// p_source = rotation * p_template + translation.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  /// Provenance: the source shape (file, kind, dimensions) and the fill method with parameters.
  nlohmann::json source = nlohmann::json::object();
  nlohmann::json method = nlohmann::json::object();
  /// Shape-error figures, when measured (see raycast/shape_error).
  nlohmann::json error = nullptr;

  /// Spheres mapped back to the source shape's frame.
  Spheres spheres_in_source_frame() const;
};

/// Builds a template from spheres given in the source frame: computes the union's mass
/// properties by ray sampling, moves the spheres to the centroid-principal frame and records the
/// transform.
ClumpTemplate make_clump_template(const Spheres& source_spheres, double density,
                                  const RaySamplingOptions& sampling = {});

/// The principal frame the DEM engine integrates a clump in: the eigenvectors of the inertia
/// tensor about the centre of mass (right-handed), or the template's own axes when its tensor is
/// already diagonal (no needless rotation of a symmetric template). An all-zero tensor stands for
/// diag(principal_moments).
struct PrincipalFrame {
  Eigen::Vector3d moments = Eigen::Vector3d::Zero();   ///< kg m^2
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  ///< columns: the axes
};
PrincipalFrame principal_frame(const MassProperties& mp);
/// The template moved into that frame (spheres relative to the centre of mass along the axes;
/// centre of mass at the origin, tensor diagonal), as DEM codes that take a template in its
/// centroid-principal frame (LIGGGHTS) need it.
ClumpTemplate in_principal_frame(const ClumpTemplate& c);

nlohmann::json to_json(const ClumpTemplate& c);
/// Throws InputError naming `where` and the field on a malformed template.
ClumpTemplate clump_from_json(const nlohmann::json& j, const std::string& where);

ClumpTemplate load_clump(const std::filesystem::path& path);
/// The same from a file's text; `where` names the file in errors.
ClumpTemplate parse_clump(const std::string& text, const std::string& where);
/// Atomic write (temporary file + rename).
void save_clump(const ClumpTemplate& c, const std::filesystem::path& path);

}  // namespace clumpkit
