#pragma once
/// Walls: triangle meshes with a material and a prescribed rigid motion. The meshes are plain
/// vertex/triangle arrays in metres (the rigs build them in code; files come through mesh_io).
#include <Eigen/Core>
#include <array>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace clumpkit::dem {

/// Vertices in metres, triangles as vertex indices (any orientation: contact is two-sided).
struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> triangles;

  /// Throws InputError(where, field) for an empty mesh, bad indices, non-finite vertices or
  /// degenerate (zero-area) triangles.
  void validate(const std::string& where, const std::string& field) const;
  void append(const TriangleMesh& other);
};

/// Piecewise-linear velocity keyframes (t_k, v_k); the first and last velocities are held
/// outside the keyed range. No keys = at rest.
struct VelocityProfile {
  std::vector<double> times;                ///< s, strictly increasing
  std::vector<Eigen::Vector3d> velocities;  ///< m/s

  static VelocityProfile constant(const Eigen::Vector3d& v) { return {{0.0}, {v}}; }
  Eigen::Vector3d velocity(double t) const;
  /// ∫_0^t v dt (exact for the piecewise-linear profile), m.
  Eigen::Vector3d displacement(double t) const;
  void validate(const std::string& where, const std::string& field) const;
};

/// Rotation at a constant rate about an axis through `axis_point` (which moves with the wall's
/// translation), between start_time and stop_time.
struct WallRotation {
  Eigen::Vector3d axis_point = Eigen::Vector3d::Zero();        ///< m, at t = 0
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();             ///< direction (normalised on use)
  double rpm = 0.0;                                            ///< revolutions per minute, signed
  double start_time = 0.0;                                     ///< s
  double stop_time = std::numeric_limits<double>::infinity();  ///< s

  double angular_speed() const;  ///< rad/s
  double angle(double t) const;  ///< rad turned by time t
};

struct WallMotion {
  VelocityProfile translation;
  std::optional<WallRotation> rotation;
  /// Throws InputError naming `where` and `field` (e.g. "walls[2].motion") for a bad motion.
  void validate(const std::string& where, const std::string& field) const;
};

struct WallSettings {
  std::string name;
  TriangleMesh mesh;     ///< at t = 0, metres
  std::string material;  ///< a MaterialLibrary name
  WallMotion motion;
  /// The wall torque is reported about this point (moving with the wall's translation), m.
  /// Defaults to the rotation axis point when the wall rotates.
  std::optional<Eigen::Vector3d> torque_reference;
};

/// Wall kinematics at time t: x(t) = R(t) (X − p0) + p0 + D(t).
struct WallPose {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d axis_point = Eigen::Vector3d::Zero();       ///< p0 + D(t)
  Eigen::Vector3d reference_point = Eigen::Vector3d::Zero();  ///< p0 at t = 0
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();         ///< translation, m/s
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();            ///< rad/s
  Eigen::Vector3d apply(const Eigen::Vector3d& x0) const {
    return rotation * (x0 - reference_point) + axis_point;
  }
  /// The inverse of apply: the wall's point at t = 0 that is at world point x now.
  Eigen::Vector3d unapply(const Eigen::Vector3d& x) const {
    return rotation.transpose() * (x - axis_point) + reference_point;
  }
  /// True when the wall is where it was at t = 0 (apply is the identity).
  bool at_rest() const { return rotation.isIdentity(0.0) && axis_point == reference_point; }
  /// Velocity of the wall material at world point x.
  Eigen::Vector3d velocity_at(const Eigen::Vector3d& x) const {
    return velocity + omega.cross(x - axis_point);
  }
};

WallPose wall_pose(const WallMotion& motion, double t);

// Meshes for rigs and tests (all closed forms, metres).

/// A flat rectangle centred at `center`, normal `normal`, side lengths `size`, split into
/// `divisions` × `divisions` squares of two triangles each.
TriangleMesh make_plane(const Eigen::Vector3d& center, const Eigen::Vector3d& normal, double size_u,
                        double size_v, int divisions = 1);
/// Lateral surface of a cylinder about the z axis through `base_center`, plus a bottom disc when
/// `bottom` is true, plus a top disc when `top` is true.
TriangleMesh make_cylinder(const Eigen::Vector3d& base_center, double radius, double height,
                           int segments, bool bottom, bool top);
/// The six faces of an axis-aligned box (two triangles each).
TriangleMesh make_box(const Eigen::Vector3d& min, const Eigen::Vector3d& max);

}  // namespace clumpkit::dem
