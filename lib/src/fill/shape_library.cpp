#include "clumpkit/fill/shape_library.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include "clumpkit/core/error.hpp"

namespace clumpkit {

using Eigen::Vector2d;
using Eigen::Vector3d;
namespace {}

// ---------------------------------------------------------------------------------------------
// Mesh utilities

double TessellatedMesh::signed_volume() const {
  double v = 0.0;
  for (const auto& t : triangles) v += vertices[t[0]].dot(vertices[t[1]].cross(vertices[t[2]]));
  return v / 6.0;
}

bool TessellatedMesh::is_closed_and_oriented() const {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if (a == b) return false;
      if (++directed[{a, b}] > 1) return false;  // same directed edge twice: flipped neighbour
    }
  for (const auto& [e, n] : directed)
    if (!directed.count({e.second, e.first})) return false;  // boundary edge
  return true;
}

std::string to_ascii_stl(const TessellatedMesh& m, const std::string& name, double scale) {
  std::string s = fmt::format("solid {}\n", name);
  for (const auto& t : m.triangles) {
    const Vector3d a = m.vertices[t[0]] * scale, b = m.vertices[t[1]] * scale,
                   c = m.vertices[t[2]] * scale;
    Vector3d n = (b - a).cross(c - a);
    if (n.norm() > 0) n.normalize();
    s += fmt::format("  facet normal {:.9g} {:.9g} {:.9g}\n    outer loop\n", n.x(), n.y(), n.z());
    for (const Vector3d* v : {&a, &b, &c})
      s += fmt::format("      vertex {:.9g} {:.9g} {:.9g}\n", v->x(), v->y(), v->z());
    s += "    endloop\n  endfacet\n";
  }
  s += fmt::format("endsolid {}\n", name);
  return s;
}

std::string to_obj(const TessellatedMesh& m, const std::string& name, double scale) {
  std::string s = fmt::format(
      "# {}: closed, outward-oriented triangle mesh written by clumpkit\no {}\n", name, name);
  for (const Vector3d& v : m.vertices)
    s += fmt::format("v {:.9g} {:.9g} {:.9g}\n", v.x() * scale, v.y() * scale, v.z() * scale);
  for (const auto& t : m.triangles) s += fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
  return s;
}

namespace {

// A mesh built from rings of vertices stacked along a profile: a ring is either a pole (one
// vertex) or `n` vertices; consecutive rings are stitched, and the last to the first if `closed`.
struct RingBuilder {
  int n;
  TessellatedMesh mesh;
  std::vector<std::pair<int, bool>> rings;  // first vertex, is pole
  void pole(const Vector3d& p) {
    rings.push_back({static_cast<int>(mesh.vertices.size()), true});
    mesh.vertices.push_back(p);
  }
  template <class F>
  void ring(F point_at) {  // point_at(j) for j in [0, n)
    rings.push_back({static_cast<int>(mesh.vertices.size()), false});
    for (int j = 0; j < n; ++j) mesh.vertices.push_back(point_at(j));
  }
  void stitch(const std::pair<int, bool>& a, const std::pair<int, bool>& b) {
    for (int j = 0; j < n; ++j) {
      const int j1 = (j + 1) % n;
      if (a.second && b.second) return;
      if (a.second) {
        mesh.triangles.push_back({a.first, b.first + j, b.first + j1});
      } else if (b.second) {
        mesh.triangles.push_back({a.first + j, b.first, a.first + j1});
      } else {
        mesh.triangles.push_back({a.first + j, b.first + j, b.first + j1});
        mesh.triangles.push_back({a.first + j, b.first + j1, a.first + j1});
      }
    }
  }
  TessellatedMesh finish(bool closed) {
    for (size_t k = 0; k + 1 < rings.size(); ++k) stitch(rings[k], rings[k + 1]);
    if (closed) stitch(rings.back(), rings.front());
    if (mesh.signed_volume() < 0)
      for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
    return std::move(mesh);
  }
};

// Surface of revolution about z of a profile (rho, z); points with rho == 0 become poles.
TessellatedMesh revolve(const std::vector<Vector2d>& profile, int n, bool closed) {
  RingBuilder b{n, {}, {}};
  for (const Vector2d& q : profile) {
    if (q.x() <= 0.0) {
      b.pole({0.0, 0.0, q.y()});
    } else {
      b.ring([&](int j) {
        const double phi = 2.0 * std::numbers::pi * j / n;
        return Vector3d(q.x() * std::cos(phi), q.x() * std::sin(phi), q.y());
      });
    }
  }
  return b.finish(closed);
}

// Subdivides a polyline into pieces no longer than `spacing`, keeping its corners.
std::vector<Vector2d> subdivide(const std::vector<Vector2d>& poly, double spacing) {
  std::vector<Vector2d> out{poly.front()};
  for (size_t k = 1; k < poly.size(); ++k) {
    const double len = (poly[k] - poly[k - 1]).norm();
    if (len <= 0.0) continue;
    const int pieces = std::max(1, static_cast<int>(std::ceil(len / spacing)));
    for (int i = 1; i <= pieces; ++i)
      out.push_back(poly[k - 1] + (poly[k] - poly[k - 1]) * (static_cast<double>(i) / pieces));
  }
  return out;
}

// Ring count and profile spacing for ~`triangles` triangles on a profile of length `length`
// swept at radius up to `rho_max` (edges about as long around as along).
void revolve_resolution(int triangles, double length, double rho_max, int& n, double& spacing) {
  n = std::max(
      8, static_cast<int>(std::lround(std::sqrt(triangles * std::numbers::pi * rho_max / length))));
  spacing = 2.0 * std::numbers::pi * rho_max / n;
}

double segment_distance(const Vector2d& p, const Vector2d& a, const Vector2d& b) {
  const Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

// Line along coordinate k of a 2-D polygon at the other coordinate q: inside intervals.
void polygon_line(const std::vector<Vector2d>& poly, int k, double q, IntervalList& out) {
  const int o = 1 - k;
  std::vector<double> xs;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vector2d& a = poly[i];
    const Vector2d& b = poly[(i + 1) % poly.size()];
    if ((a[o] <= q) != (b[o] <= q)) xs.push_back(a[k] + (q - a[o]) / (b[o] - a[o]) * (b[k] - a[k]));
  }
  std::sort(xs.begin(), xs.end());
  for (size_t i = 0; i + 1 < xs.size(); i += 2)
    if (xs[i + 1] > xs[i]) out.push_back({xs[i], xs[i + 1]});
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Chamfered cylinder

ChamferedCylinder::ChamferedCylinder(double diameter, double height, double chamfer)
    : r_(0.5 * diameter), h_(height), c_(chamfer) {
  if (!(r_ > 0 && h_ > 0 && c_ >= 0 && c_ < std::min(r_, 0.5 * h_)))
    throw InputError("", "chamfer", "needs diameter, height > 0 and 0 <= chamfer < min(D/2, H/2)");
}

Eigen::AlignedBox3d ChamferedCylinder::bounds() const {
  return {Vector3d(-r_, -r_, -0.5 * h_), Vector3d(r_, r_, 0.5 * h_)};
}

void ChamferedCylinder::intervals(const Vector3d& o, int axis, IntervalList& out) const {
  out.clear();
  const double k = r_ + 0.5 * h_ - c_;  // chamfer cone: rho + |z| <= k
  if (axis == 2) {
    const double rho = std::hypot(o.x(), o.y());
    if (rho >= r_) return;
    const double hz = std::min(0.5 * h_, k - rho);
    if (hz > 0) out.push_back({-hz, hz});
    return;
  }
  const double az = std::abs(o.z());
  if (az >= 0.5 * h_) return;
  const double rmax = std::min(r_, k - az);
  const double w = axis == 0 ? o.y() : o.x();
  const double c2 = rmax * rmax - w * w;
  if (c2 > 0 && rmax > 0) out.push_back({-std::sqrt(c2), std::sqrt(c2)});
}

double ChamferedCylinder::signed_distance(const Vector3d& p) const {
  const Vector2d q(std::hypot(p.x(), p.y()), std::abs(p.z()));
  const double hz = 0.5 * h_;
  const Vector2d a(0.0, hz), b(r_ - c_, hz), c(r_, hz - c_), d(r_, 0.0);
  double dist = std::min(segment_distance(q, a, b), segment_distance(q, c, d));
  if (c_ > 0) dist = std::min(dist, segment_distance(q, b, c));
  const bool inside = q.x() < r_ && q.y() < hz && q.x() + q.y() < r_ + hz - c_;
  return inside ? -dist : dist;
}

double ChamferedCylinder::volume() const {
  return std::numbers::pi * r_ * r_ * h_ - 2.0 * std::numbers::pi * c_ * c_ * (r_ - c_ / 3.0);
}

TessellatedMesh ChamferedCylinder::tessellate(int triangles) const {
  const double hz = 0.5 * h_;
  std::vector<Vector2d> prof = {{0, -hz}, {r_ - c_, -hz}};
  if (c_ > 0) prof.push_back({r_, -hz + c_});
  if (c_ > 0)
    prof.push_back({r_, hz - c_});
  else
    prof.push_back({r_, hz});
  if (c_ > 0) prof.push_back({r_ - c_, hz});
  prof.push_back({0, hz});
  if (c_ == 0) prof = {{0, -hz}, {r_, -hz}, {r_, hz}, {0, hz}};
  double len = 0;
  for (size_t k = 1; k < prof.size(); ++k) len += (prof[k] - prof[k - 1]).norm();
  int n;
  double spacing;
  revolve_resolution(triangles, len, r_, n, spacing);
  return revolve(subdivide(prof, spacing), n, false);
}

// ---------------------------------------------------------------------------------------------
// Ellipsoid

Ellipsoid::Ellipsoid(double a, double b, double c) : a_(a), b_(b), c_(c) {
  if (!(a > 0 && b > 0 && c > 0)) throw InputError("", "semi_axes", "must be positive");
}

Eigen::AlignedBox3d Ellipsoid::bounds() const {
  return {-Vector3d(a_, b_, c_), Vector3d(a_, b_, c_)};
}

void Ellipsoid::intervals(const Vector3d& o, int axis, IntervalList& out) const {
  out.clear();
  const Vector3d s(a_, b_, c_);
  double rest = 1.0;
  for (int k = 0; k < 3; ++k)
    if (k != axis) rest -= (o[k] / s[k]) * (o[k] / s[k]);
  if (rest <= 0) return;
  const double t = s[axis] * std::sqrt(rest);
  out.push_back({-t, t});
}

double Ellipsoid::signed_distance(const Vector3d& p) const {
  const double f =
      (p.x() / a_) * (p.x() / a_) + (p.y() / b_) * (p.y() / b_) + (p.z() / c_) * (p.z() / c_);
  if (a_ != b_) return (std::sqrt(f) - 1.0) * std::min({a_, b_, c_});  // sign only
  // Spheroid: distance to the ellipse (a cos t, c sin t) in the meridian quadrant.
  const Vector2d q(std::hypot(p.x(), p.y()), std::abs(p.z()));
  auto d2 = [&](double t) {
    return (q - Vector2d(a_ * std::cos(t), c_ * std::sin(t))).squaredNorm();
  };
  const int scan = 64;
  int best = 0;
  for (int i = 1; i <= scan; ++i)
    if (d2(0.5 * std::numbers::pi * i / scan) < d2(0.5 * std::numbers::pi * best / scan)) best = i;
  double lo = 0.5 * std::numbers::pi * std::max(0, best - 1) / scan,
         hi = 0.5 * std::numbers::pi * std::min(scan, best + 1) / scan;
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int it = 0; it < 60; ++it) {
    const double m1 = hi - g * (hi - lo), m2 = lo + g * (hi - lo);
    if (d2(m1) < d2(m2))
      hi = m2;
    else
      lo = m1;
  }
  const double d = std::sqrt(d2(0.5 * (lo + hi)));
  return f < 1.0 ? -d : d;
}

double Ellipsoid::volume() const {
  return 4.0 / 3.0 * std::numbers::pi * a_ * b_ * c_;
}

TessellatedMesh Ellipsoid::tessellate(int triangles) const {
  const int n = std::max(8, static_cast<int>(std::lround(std::sqrt(triangles * 1.0))));
  const int m = std::max(4, triangles / (2 * n) + 1);
  RingBuilder b{n, {}, {}};
  b.pole({0, 0, -c_});
  for (int i = 1; i < m; ++i) {
    const double th = std::numbers::pi * i / m;
    b.ring([&](int j) {
      const double phi = 2.0 * std::numbers::pi * j / n;
      return Vector3d(a_ * std::sin(th) * std::cos(phi), b_ * std::sin(th) * std::sin(phi),
                      -c_ * std::cos(th));
    });
  }
  b.pole({0, 0, c_});
  return b.finish(false);
}

// ---------------------------------------------------------------------------------------------
// Capsule

Capsule::Capsule(double radius, double length) : r_(radius), l_(length) {
  if (!(r_ > 0 && l_ >= 0)) throw InputError("", "capsule", "radius > 0 and length >= 0 needed");
}

Eigen::AlignedBox3d Capsule::bounds() const {
  return {Vector3d(-r_, -r_, -0.5 * l_ - r_), Vector3d(r_, r_, 0.5 * l_ + r_)};
}

void Capsule::intervals(const Vector3d& o, int axis, IntervalList& out) const {
  out.clear();
  if (axis == 2) {
    const double rho2 = o.x() * o.x() + o.y() * o.y();
    if (rho2 >= r_ * r_) return;
    const double hz = 0.5 * l_ + std::sqrt(r_ * r_ - rho2);
    out.push_back({-hz, hz});
    return;
  }
  const double w = axis == 0 ? o.y() : o.x();
  const double dz = std::max(0.0, std::abs(o.z()) - 0.5 * l_);
  const double c2 = r_ * r_ - w * w - dz * dz;
  if (c2 > 0) out.push_back({-std::sqrt(c2), std::sqrt(c2)});
}

double Capsule::signed_distance(const Vector3d& p) const {
  const double z = std::clamp(p.z(), -0.5 * l_, 0.5 * l_);
  return (p - Vector3d(0, 0, z)).norm() - r_;
}

double Capsule::volume() const {
  return std::numbers::pi * r_ * r_ * l_ + 4.0 / 3.0 * std::numbers::pi * r_ * r_ * r_;
}

TessellatedMesh Capsule::tessellate(int triangles) const {
  const double len = std::numbers::pi * r_ + l_;
  int n;
  double spacing;
  revolve_resolution(triangles, len, r_, n, spacing);
  const int arc = std::max(2, static_cast<int>(std::ceil(0.5 * std::numbers::pi * r_ / spacing)));
  std::vector<Vector2d> prof;
  for (int i = 0; i <= arc; ++i) {
    const double t = -0.5 * std::numbers::pi + 0.5 * std::numbers::pi * i / arc;
    prof.push_back({r_ * std::cos(t), -0.5 * l_ + r_ * std::sin(t)});
  }
  if (l_ > 0) {
    const auto mid = subdivide({{r_, -0.5 * l_}, {r_, 0.5 * l_}}, spacing);
    prof.insert(prof.end(), mid.begin() + 1, mid.end());
  }
  for (int i = 1; i <= arc; ++i) {
    const double t = 0.5 * std::numbers::pi * i / arc;
    prof.push_back({i == arc ? 0.0 : r_ * std::cos(t), 0.5 * l_ + r_ * std::sin(t)});
  }
  prof.front().x() = 0.0;
  return revolve(prof, n, false);
}

// ---------------------------------------------------------------------------------------------
// Torus

Torus::Torus(double major_radius, double minor_radius) : R_(major_radius), r_(minor_radius) {
  if (!(r_ > 0 && R_ > r_)) throw InputError("", "torus", "needs major radius > minor radius > 0");
}

Eigen::AlignedBox3d Torus::bounds() const {
  return {Vector3d(-R_ - r_, -R_ - r_, -r_), Vector3d(R_ + r_, R_ + r_, r_)};
}

void Torus::intervals(const Vector3d& o, int axis, IntervalList& out) const {
  out.clear();
  if (axis == 2) {
    const double d = std::hypot(o.x(), o.y()) - R_;
    const double c2 = r_ * r_ - d * d;
    if (c2 > 0) out.push_back({-std::sqrt(c2), std::sqrt(c2)});
    return;
  }
  const double s2 = r_ * r_ - o.z() * o.z();
  if (s2 <= 0) return;
  const double s = std::sqrt(s2);
  const double w = axis == 0 ? o.y() : o.x();
  const double hi = (R_ + s) * (R_ + s) - w * w;
  if (hi <= 0) return;
  const double lo = (R_ - s) * (R_ - s) - w * w;
  if (lo <= 0) {
    out.push_back({-std::sqrt(hi), std::sqrt(hi)});
  } else {
    out.push_back({-std::sqrt(hi), -std::sqrt(lo)});
    out.push_back({std::sqrt(lo), std::sqrt(hi)});
  }
}

double Torus::signed_distance(const Vector3d& p) const {
  return std::hypot(std::hypot(p.x(), p.y()) - R_, p.z()) - r_;
}

double Torus::volume() const {
  return 2.0 * std::numbers::pi * std::numbers::pi * R_ * r_ * r_;
}

TessellatedMesh Torus::tessellate(int triangles) const {
  // Edges of similar length around the tube (2 pi r / m) and around z (2 pi R / n).
  const int m = std::max(8, static_cast<int>(std::lround(std::sqrt(0.5 * triangles * r_ / R_))));
  const int n = std::max(8, triangles / (2 * m));
  std::vector<Vector2d> prof;
  for (int i = 0; i < m; ++i) {
    const double t = 2.0 * std::numbers::pi * i / m;
    prof.push_back({R_ + r_ * std::cos(t), r_ * std::sin(t)});
  }
  return revolve(prof, n, true);
}

// ---------------------------------------------------------------------------------------------
// Superellipsoid

Superellipsoid::Superellipsoid(const Vector3d& semi_axes, double e1, double e2)
    : s_(semi_axes), e1_(e1), e2_(e2) {
  if (!((s_.array() > 0).all() && e1 > 0 && e1 < 2 && e2 > 0 && e2 < 2))
    throw InputError("", "superellipsoid", "semi-axes > 0 and exponents in (0, 2) needed");
  // Jaklic, Leonardis and Solina (2000), eq. 2.60.
  auto beta = [](double x, double y) {
    return std::tgamma(x) * std::tgamma(y) / std::tgamma(x + y);
  };
  volume_ = 2.0 * s_.prod() * e1_ * e2_ * beta(0.5 * e1_ + 1.0, e1_) * beta(0.5 * e2_, 0.5 * e2_);
}

Eigen::AlignedBox3d Superellipsoid::bounds() const {
  return {-s_, s_};
}

double Superellipsoid::inside_function(const Vector3d& p) const {
  const double xy =
      std::pow(std::abs(p.x() / s_.x()), 2.0 / e2_) + std::pow(std::abs(p.y() / s_.y()), 2.0 / e2_);
  return std::pow(xy, e2_ / e1_) + std::pow(std::abs(p.z() / s_.z()), 2.0 / e1_);
}

void Superellipsoid::intervals(const Vector3d& o, int axis, IntervalList& out) const {
  out.clear();
  if (axis == 2) {
    const double xy = std::pow(std::abs(o.x() / s_.x()), 2.0 / e2_) +
                      std::pow(std::abs(o.y() / s_.y()), 2.0 / e2_);
    const double rem = 1.0 - std::pow(xy, e2_ / e1_);
    if (rem <= 0) return;
    const double t = s_.z() * std::pow(rem, 0.5 * e1_);
    out.push_back({-t, t});
    return;
  }
  const double rem = 1.0 - std::pow(std::abs(o.z() / s_.z()), 2.0 / e1_);
  if (rem <= 0) return;
  const int w = axis == 0 ? 1 : 0;
  const double q = std::pow(rem, e1_ / e2_) - std::pow(std::abs(o[w] / s_[w]), 2.0 / e2_);
  if (q <= 0) return;
  const double t = s_[axis] * std::pow(q, 0.5 * e2_);
  out.push_back({-t, t});
}

double Superellipsoid::signed_distance(const Vector3d& p) const {
  return (std::pow(inside_function(p), 0.5 * e1_) - 1.0) * s_.minCoeff();
}

TessellatedMesh Superellipsoid::tessellate(int triangles) const {
  const int n = std::max(8, static_cast<int>(std::lround(std::sqrt(triangles * 1.0))));
  const int m = std::max(4, triangles / (2 * n) + 1);
  auto spow = [](double v, double e) { return std::copysign(std::pow(std::abs(v), e), v); };
  RingBuilder b{n, {}, {}};
  b.pole({0, 0, -s_.z()});
  for (int i = 1; i < m; ++i) {
    const double eta = -0.5 * std::numbers::pi + std::numbers::pi * i / m;
    b.ring([&](int j) {
      const double om = 2.0 * std::numbers::pi * j / n;
      const double ce = spow(std::cos(eta), e1_);
      return Vector3d(s_.x() * ce * spow(std::cos(om), e2_), s_.y() * ce * spow(std::sin(om), e2_),
                      s_.z() * spow(std::sin(eta), e1_));
    });
  }
  b.pole({0, 0, s_.z()});
  return b.finish(false);
}

// ---------------------------------------------------------------------------------------------
// Convex polytope

ConvexPolytope::ConvexPolytope(std::vector<Plane> planes) : planes_(std::move(planes)) {
  for (Plane& p : planes_) {
    const double nn = p.normal.norm();
    p.normal /= nn;
    p.offset /= nn;
  }
  double scale = 0;
  for (const Plane& p : planes_) scale = std::max(scale, std::abs(p.offset));
  const double eps = 1e-9 * scale;
  // Vertices: feasible intersections of plane triples, merged.
  std::vector<Vector3d> verts;
  const int np = static_cast<int>(planes_.size());
  for (int i = 0; i < np; ++i)
    for (int j = i + 1; j < np; ++j)
      for (int k = j + 1; k < np; ++k) {
        Eigen::Matrix3d a;
        a.row(0) = planes_[i].normal;
        a.row(1) = planes_[j].normal;
        a.row(2) = planes_[k].normal;
        if (std::abs(a.determinant()) < 1e-9) continue;
        const Vector3d v =
            a.inverse() * Vector3d(planes_[i].offset, planes_[j].offset, planes_[k].offset);
        bool ok = true;
        for (const Plane& p : planes_) ok = ok && p.normal.dot(v) <= p.offset + eps;
        if (!ok) continue;
        bool dup = false;
        for (const Vector3d& w : verts) dup = dup || (w - v).norm() < 1e3 * eps;
        if (!dup) verts.push_back(v);
      }
  if (verts.size() < 4) throw InputError("", "planes", "the half-spaces do not bound a solid");
  bounds_.setEmpty();
  for (const Vector3d& v : verts) bounds_.extend(v);
  mesh_.vertices = verts;
  for (const Plane& p : planes_) {
    std::vector<int> on;
    for (int v = 0; v < static_cast<int>(verts.size()); ++v)
      if (std::abs(p.normal.dot(verts[v]) - p.offset) < 1e3 * eps) on.push_back(v);
    if (on.size() < 3) continue;
    Vector3d c = Vector3d::Zero();
    for (int v : on) c += verts[v];
    c /= static_cast<double>(on.size());
    const Vector3d e1 = (verts[on[0]] - c).normalized(), e2 = p.normal.cross(e1);
    std::sort(on.begin(), on.end(), [&](int a, int b) {
      return std::atan2((verts[a] - c).dot(e2), (verts[a] - c).dot(e1)) <
             std::atan2((verts[b] - c).dot(e2), (verts[b] - c).dot(e1));
    });
    for (size_t k = 1; k + 1 < on.size(); ++k) mesh_.triangles.push_back({on[0], on[k], on[k + 1]});
  }
  volume_ = mesh_.signed_volume();
}

void ConvexPolytope::intervals(const Vector3d& o, int axis, IntervalList& out) const {
  out.clear();
  double lo = -1e300, hi = 1e300;
  for (const Plane& p : planes_) {
    // n_a t + (n . o without axis) <= d
    double rest = p.offset;
    for (int k = 0; k < 3; ++k)
      if (k != axis) rest -= p.normal[k] * o[k];
    const double na = p.normal[axis];
    if (na > 0)
      hi = std::min(hi, rest / na);
    else if (na < 0)
      lo = std::max(lo, rest / na);
    else if (rest < 0)
      return;
  }
  if (hi > lo) out.push_back({lo, hi});
}

double ConvexPolytope::signed_distance(const Vector3d& p) const {
  double d = -1e300;
  for (const Plane& pl : planes_) d = std::max(d, pl.normal.dot(p) - pl.offset);
  return d;
}

// ---------------------------------------------------------------------------------------------
// Extruded polygon

ExtrudedPolygon::ExtrudedPolygon(std::vector<Vector2d> polygon, double width,
                                 std::vector<std::array<int, 3>> triangulation)
    : poly_(std::move(polygon)), w_(width), tri_(std::move(triangulation)) {}

Eigen::AlignedBox3d ExtrudedPolygon::bounds() const {
  Eigen::AlignedBox3d b;
  b.setEmpty();
  for (const Vector2d& q : poly_) {
    b.extend(Vector3d(q.x(), -0.5 * w_, q.y()));
    b.extend(Vector3d(q.x(), 0.5 * w_, q.y()));
  }
  return b;
}

bool ExtrudedPolygon::inside_2d(const Vector2d& q) const {
  IntervalList l;
  polygon_line(poly_, 0, q.y(), l);
  for (const Interval& iv : l)
    if (q.x() > iv.t0 && q.x() < iv.t1) return true;
  return false;
}

void ExtrudedPolygon::intervals(const Vector3d& o, int axis, IntervalList& out) const {
  out.clear();
  if (axis == 1) {
    if (inside_2d({o.x(), o.z()})) out.push_back({-0.5 * w_, 0.5 * w_});
    return;
  }
  if (std::abs(o.y()) >= 0.5 * w_) return;
  if (axis == 0)
    polygon_line(poly_, 0, o.z(), out);
  else
    polygon_line(poly_, 1, o.x(), out);
}

double ExtrudedPolygon::signed_distance(const Vector3d& p) const {
  const Vector2d q(p.x(), p.z());
  double d2 = 1e300;
  for (size_t i = 0; i < poly_.size(); ++i)
    d2 = std::min(d2, segment_distance(q, poly_[i], poly_[(i + 1) % poly_.size()]));
  if (inside_2d(q)) d2 = -d2;
  const double dy = std::abs(p.y()) - 0.5 * w_;
  return std::hypot(std::max(d2, 0.0), std::max(dy, 0.0)) + std::min(std::max(d2, dy), 0.0);
}

double ExtrudedPolygon::volume() const {
  double a = 0;
  for (size_t i = 0; i < poly_.size(); ++i) {
    const Vector2d& p = poly_[i];
    const Vector2d& q = poly_[(i + 1) % poly_.size()];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * std::abs(a) * w_;
}

TessellatedMesh ExtrudedPolygon::tessellate(int) const {
  TessellatedMesh m;
  const int n = static_cast<int>(poly_.size());
  for (double y : {-0.5 * w_, 0.5 * w_})
    for (const Vector2d& q : poly_) m.vertices.push_back({q.x(), y, q.y()});
  auto add = [&](std::array<int, 3> t, const Vector3d& outward) {
    const Vector3d nrm =
        (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
    if (nrm.dot(outward) < 0) std::swap(t[1], t[2]);
    m.triangles.push_back(t);
  };
  for (const auto& t : tri_) {
    add({t[0], t[1], t[2]}, -Vector3d::UnitY());
    add({t[0] + n, t[1] + n, t[2] + n}, Vector3d::UnitY());
  }
  const bool ccw = volume() > 0 && [&] {
    double a = 0;
    for (int i = 0; i < n; ++i)
      a += poly_[i].x() * poly_[(i + 1) % n].y() - poly_[(i + 1) % n].x() * poly_[i].y();
    return a > 0;
  }();
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    const Vector2d e = poly_[j] - poly_[i];
    // Outward normal of an edge of a counter-clockwise polygon in (x, z) is (e.z, -e.x).
    Vector3d out(e.y(), 0.0, -e.x());
    if (!ccw) out = -out;
    add({i, j, j + n}, out);
    add({i, j + n, i + n}, out);
  }
  return m;
}

// ---------------------------------------------------------------------------------------------
// The test set

namespace {
constexpr double mm = 1e-3;

std::uint64_t splitmix(std::uint64_t& x) {
  std::uint64_t z = (x += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
double uniform(std::uint64_t& s) {
  return static_cast<double>(splitmix(s) >> 11) * 0x1.0p-53;
}

struct Entry {
  const char* name;
  const char* description;
};
const Entry kShapes[] = {
    {"pill_A", "cylinder D 6.0 mm x H 5.4 mm, sharp edges"},
    {"pill_B", "cylinder D 6.0 mm x H 5.8 mm, sharp edges"},
    {"pill_C", "cylinder D 6.0 mm x H 6.2 mm, sharp edges"},
    {"pill_A_chamfered", "cylinder D 6.0 mm x H 5.4 mm, 0.5 mm 45-degree chamfers"},
    {"pill_B_chamfered", "cylinder D 6.0 mm x H 5.8 mm, 0.5 mm 45-degree chamfers"},
    {"pill_C_chamfered", "cylinder D 6.0 mm x H 6.2 mm, 0.5 mm 45-degree chamfers"},
    {"ellipsoid", "spheroid 2:1:1, semi-axes 2 x 2 x 4 mm (long axis z)"},
    {"capsule", "capsule radius 2 mm, straight length 4 mm (8 mm overall, axis z)"},
    {"cube", "cube, edge 5 mm"},
    {"seed", "superellipsoid grain, semi-axes 2.2 x 1.8 x 4.0 mm, e1 1.4 (pointed ends), e2 1.0"},
    {"rock", "random convex polytope (24 planes, ~6 x 5 x 4 mm), seeded"},
    {"torus", "torus R 3 mm, tube radius 1.2 mm"},
    {"bracket", "L-shaped bracket: legs 8 x 2 mm and 6 x 2 mm in xz, 4 mm wide (non-convex)"},
};
}  // namespace

const std::vector<std::string>& test_shape_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const Entry& e : kShapes) v.push_back(e.name);
    return v;
  }();
  return names;
}

bool is_test_shape(const std::string& name) {
  const auto& names = test_shape_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::string test_shape_description(const std::string& name) {
  for (const Entry& e : kShapes)
    if (name == e.name) return e.description;
  return "";
}

std::shared_ptr<const AnalyticSolid> make_test_shape(const std::string& name, std::uint64_t seed) {
  const double heights[] = {5.4, 5.8, 6.2};
  for (int k = 0; k < 3; ++k) {
    const std::string p = std::string("pill_") + static_cast<char>('A' + k);
    if (name == p) return std::make_shared<ChamferedCylinder>(6.0 * mm, heights[k] * mm, 0.0);
    if (name == p + "_chamfered")
      return std::make_shared<ChamferedCylinder>(6.0 * mm, heights[k] * mm, 0.5 * mm);
  }
  if (name == "ellipsoid") return std::make_shared<Ellipsoid>(2 * mm, 2 * mm, 4 * mm);
  if (name == "capsule") return std::make_shared<Capsule>(2 * mm, 4 * mm);
  if (name == "torus") return std::make_shared<Torus>(3 * mm, 1.2 * mm);
  if (name == "seed")
    return std::make_shared<Superellipsoid>(Vector3d(2.2, 1.8, 4.0) * mm, 1.4, 1.0);
  if (name == "cube") {
    std::vector<ConvexPolytope::Plane> planes;
    for (int k = 0; k < 3; ++k)
      for (double s : {-1.0, 1.0}) planes.push_back({s * Vector3d::Unit(k), 2.5 * mm});
    return std::make_shared<ConvexPolytope>(planes);
  }
  if (name == "rock") {
    std::uint64_t s = seed * 0x2545F4914F6CDD1Dull + 7;
    const Vector3d stretch(1.0, 0.8, 0.65);
    std::vector<ConvexPolytope::Plane> planes;
    for (int i = 0; i < 24; ++i) {
      const double z = 2.0 * uniform(s) - 1.0, phi = 2.0 * std::numbers::pi * uniform(s);
      const double rxy = std::sqrt(1.0 - z * z);
      const Vector3d n(rxy * std::cos(phi), rxy * std::sin(phi), z);
      const double d = 3.0 * mm * (0.85 + 0.3 * uniform(s));
      // Plane in the unit space n . y <= d, mapped by x = diag(stretch) y.
      planes.push_back({n.cwiseQuotient(stretch), d});
    }
    for (int k = 0; k < 3; ++k)  // caps keep the polytope bounded whatever the draw
      for (double sg : {-1.0, 1.0})
        planes.push_back({sg * Vector3d::Unit(k), 3.6 * mm * stretch[k]});
    return std::make_shared<ConvexPolytope>(planes);
  }
  if (name == "bracket") {
    std::vector<Vector2d> poly = {{0, 0}, {8, 0}, {8, 2}, {2, 2}, {2, 6}, {0, 6}};
    for (Vector2d& q : poly) q = (q - Vector2d(3.0, 2.0)) * mm;
    return std::make_shared<ExtrudedPolygon>(
        poly, 4 * mm, std::vector<std::array<int, 3>>{{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}});
  }
  std::string list;
  for (const std::string& n : test_shape_names()) list += (list.empty() ? "" : ", ") + n;
  throw InputError("", "SHAPE", "unknown test shape '" + name + "' (known: " + list + ")");
}

}  // namespace clumpkit
