#include "clumpkit/dem/wall.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "clumpkit/core/error.hpp"

namespace clumpkit::dem {

void TriangleMesh::validate(const std::string& where, const std::string& field) const {
  if (vertices.empty() || triangles.empty())
    throw InputError(where, field, "the wall mesh has no triangles");
  for (size_t i = 0; i < vertices.size(); ++i)
    if (!vertices[i].allFinite())
      throw InputError(where, field + ".vertices[" + std::to_string(i) + "]",
                       "vertex coordinate is not finite");
  const int n = static_cast<int>(vertices.size());
  for (size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    for (int k = 0; k < 3; ++k)
      if (tri[k] < 0 || tri[k] >= n)
        throw InputError(
            where, field + ".triangles[" + std::to_string(t) + "]",
            "vertex index " + std::to_string(tri[k]) + " is outside 0.." + std::to_string(n - 1));
    const Eigen::Vector3d e1 = vertices[tri[1]] - vertices[tri[0]];
    const Eigen::Vector3d e2 = vertices[tri[2]] - vertices[tri[0]];
    const double scale = std::max(e1.squaredNorm(), e2.squaredNorm());
    if (!(e1.cross(e2).norm() > 1e-12 * scale))
      throw InputError(where, field + ".triangles[" + std::to_string(t) + "]",
                       "degenerate (zero-area) triangle");
  }
}

void TriangleMesh::append(const TriangleMesh& other) {
  const int base = static_cast<int>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  for (auto t : other.triangles) triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

Eigen::Vector3d VelocityProfile::velocity(double t) const {
  if (times.empty()) return Eigen::Vector3d::Zero();
  if (t <= times.front()) return velocities.front();
  if (t >= times.back()) return velocities.back();
  const size_t k = std::upper_bound(times.begin(), times.end(), t) - times.begin();
  const double a = (t - times[k - 1]) / (times[k] - times[k - 1]);
  return (1.0 - a) * velocities[k - 1] + a * velocities[k];
}

Eigen::Vector3d VelocityProfile::displacement(double t) const {
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  if (times.empty() || t <= 0.0) return d;
  // Integrate piece by piece from 0 to t; before the first key and after the last the
  // velocity is held.
  double prev = 0.0;
  auto add = [&](double t0, double t1) {  // exact for linear velocity on [t0, t1]
    if (t1 <= t0) return;
    d += 0.5 * (velocity(t0) + velocity(t1)) * (t1 - t0);
  };
  for (double key : times) {
    if (key <= prev) continue;
    if (key >= t) break;
    add(prev, key);
    prev = key;
  }
  add(prev, t);
  return d;
}

void VelocityProfile::validate(const std::string& where, const std::string& field) const {
  if (times.size() != velocities.size())
    throw InputError(where, field, "times and velocities differ in length");
  for (size_t k = 0; k < times.size(); ++k) {
    if (!std::isfinite(times[k]) || !velocities[k].allFinite())
      throw InputError(where, field + "[" + std::to_string(k) + "]", "value is not finite");
    if (k > 0 && !(times[k] > times[k - 1]))
      throw InputError(where, field + "[" + std::to_string(k) + "]",
                       "times must increase strictly");
  }
}

double WallRotation::angular_speed() const {
  return rpm * 2.0 * std::numbers::pi / 60.0;
}

double WallRotation::angle(double t) const {
  const double span = std::clamp(t, start_time, std::max(start_time, stop_time)) - start_time;
  return angular_speed() * span;
}

WallPose wall_pose(const WallMotion& motion, double t) {
  WallPose p;
  const Eigen::Vector3d d = motion.translation.displacement(t);
  p.velocity = motion.translation.velocity(t);
  if (motion.rotation) {
    const WallRotation& r = *motion.rotation;
    const Eigen::Vector3d axis = r.axis.normalized();
    p.rotation = Eigen::AngleAxisd(r.angle(t), axis).toRotationMatrix();
    p.reference_point = r.axis_point;
    p.axis_point = r.axis_point + d;
    if (t >= r.start_time && t < r.stop_time) p.omega = r.angular_speed() * axis;
  } else {
    p.axis_point = d;
  }
  return p;
}

TriangleMesh make_plane(const Eigen::Vector3d& center, const Eigen::Vector3d& normal, double size_u,
                        double size_v, int divisions) {
  const Eigen::Vector3d n = normal.normalized();
  const Eigen::Vector3d helper =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = (helper - helper.dot(n) * n).normalized();
  const Eigen::Vector3d v = n.cross(u);
  TriangleMesh m;
  const int d = std::max(1, divisions);
  for (int j = 0; j <= d; ++j)
    for (int i = 0; i <= d; ++i)
      m.vertices.push_back(center + (size_u * (double(i) / d - 0.5)) * u +
                           (size_v * (double(j) / d - 0.5)) * v);
  for (int j = 0; j < d; ++j)
    for (int i = 0; i < d; ++i) {
      const int a = j * (d + 1) + i, b = a + 1, c = a + (d + 1), e = c + 1;
      m.triangles.push_back({a, b, e});
      m.triangles.push_back({a, e, c});
    }
  return m;
}

TriangleMesh make_cylinder(const Eigen::Vector3d& base, double radius, double height, int segments,
                           bool bottom, bool top) {
  TriangleMesh m;
  const int s = std::max(3, segments);
  for (int k = 0; k < s; ++k) {
    const double a = 2.0 * std::numbers::pi * k / s;
    const Eigen::Vector3d off(radius * std::cos(a), radius * std::sin(a), 0.0);
    m.vertices.push_back(base + off);
    m.vertices.push_back(base + off + Eigen::Vector3d(0, 0, height));
  }
  for (int k = 0; k < s; ++k) {
    const int a = 2 * k, b = 2 * ((k + 1) % s);
    m.triangles.push_back({a, b, b + 1});
    m.triangles.push_back({a, b + 1, a + 1});
  }
  auto disc = [&](double z, int parity) {
    const int c = static_cast<int>(m.vertices.size());
    m.vertices.push_back(base + Eigen::Vector3d(0, 0, z));
    for (int k = 0; k < s; ++k) {
      const int a = 2 * k + parity, b = 2 * ((k + 1) % s) + parity;
      m.triangles.push_back({c, a, b});
    }
  };
  if (bottom) disc(0.0, 0);
  if (top) disc(height, 1);
  return m;
}

TriangleMesh make_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  TriangleMesh m;
  for (int k = 0; k < 8; ++k)
    m.vertices.emplace_back((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(),
                            (k & 4) ? hi.z() : lo.z());
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

void WallMotion::validate(const std::string& where, const std::string& field) const {
  translation.validate(where, field + ".translation");
  if (!rotation) return;
  const WallRotation& r = *rotation;
  if (!r.axis_point.allFinite() || !std::isfinite(r.rpm) || !std::isfinite(r.start_time))
    throw InputError(where, field + ".rotation", "values must be finite");
  if (!(r.axis.norm() > 0.0))
    throw InputError(where, field + ".rotation.axis", "the axis must not be zero");
  if (!(r.stop_time >= r.start_time))
    throw InputError(where, field + ".rotation.stop_time", "stops before it starts");
}

}  // namespace clumpkit::dem
