#include "clumpkit/raycast/analytic_surfaces.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "clumpkit/core/error.hpp"

namespace clumpkit {

namespace {
// Uniform direction on the unit sphere.
Eigen::Vector3d unit_direction(SplitMix& rng) {
  const double z = 2.0 * rng.uniform() - 1.0;
  const double phi = 2.0 * std::numbers::pi * rng.uniform();
  const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}
}  // namespace

double CylinderSurface::surface_distance(const Eigen::Vector3d& p) const {
  return std::abs(cyl_.signed_distance(p));
}

std::vector<Eigen::Vector3d> CylinderSurface::sample_surface(std::size_t n,
                                                             std::uint64_t seed) const {
  const double r = 0.5 * cyl_.diameter(), h = cyl_.height();
  const double side = 2.0 * std::numbers::pi * r * h, cap = std::numbers::pi * r * r;
  SplitMix rng(seed);
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double pick = rng.uniform() * (side + 2.0 * cap);
    const double phi = 2.0 * std::numbers::pi * rng.uniform();
    if (pick < side) {
      pts.emplace_back(r * std::cos(phi), r * std::sin(phi), (rng.uniform() - 0.5) * h);
    } else {
      const double rho = r * std::sqrt(rng.uniform());
      pts.emplace_back(rho * std::cos(phi), rho * std::sin(phi),
                       pick < side + cap ? -0.5 * h : 0.5 * h);
    }
  }
  return pts;
}

SphereUnionSurface::SphereUnionSurface(Spheres spheres)
    : union_((validate_spheres(spheres, "clump"), std::move(spheres))) {
  const Spheres& s = union_.spheres();
  tol_ = 1e-12 * std::max(1e-300, union_.bounds().diagonal().norm());
  const int n = static_cast<int>(s.size());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const Eigen::Vector3d a = s[j].center - s[i].center;
      const double d = a.norm();
      if (d <= std::abs(s[i].radius - s[j].radius) || d >= s[i].radius + s[j].radius) continue;
      const double x = (d * d + s[i].radius * s[i].radius - s[j].radius * s[j].radius) / (2 * d);
      const double rho2 = s[i].radius * s[i].radius - x * x;
      if (rho2 <= 0) continue;
      circles_.push_back({s[i].center + (x / d) * a, a / d, std::sqrt(rho2), i, j});
    }
  // Triple points: where three spheres meet, kept if no fourth sphere covers them.
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (int k = j + 1; k < n; ++k) {
        const Eigen::Vector3d a = s[j].center - s[i].center, b = s[k].center - s[i].center;
        const Eigen::Vector3d nrm = a.cross(b);
        const double nn = nrm.squaredNorm();
        if (nn <= 1e-24 * a.squaredNorm() * b.squaredNorm()) continue;  // collinear centres
        const double ri2 = s[i].radius * s[i].radius;
        const double alpha = 0.5 * (ri2 - s[j].radius * s[j].radius + a.squaredNorm());
        const double beta = 0.5 * (ri2 - s[k].radius * s[k].radius + b.squaredNorm());
        Eigen::Matrix2d g;
        g << a.dot(a), a.dot(b), a.dot(b), b.dot(b);
        const Eigen::Vector2d lm = g.inverse() * Eigen::Vector2d(alpha, beta);
        const Eigen::Vector3d p0 = lm[0] * a + lm[1] * b;
        const double h2 = (ri2 - p0.squaredNorm()) / nn;
        if (h2 < 0) continue;
        for (double sign : {-1.0, 1.0}) {
          const Eigen::Vector3d q = s[i].center + p0 + sign * std::sqrt(h2) * nrm;
          if (on_boundary(q, i, j, k)) vertices_.push_back(q);
        }
      }
}

bool SphereUnionSurface::on_boundary(const Eigen::Vector3d& q, int a, int b, int c) const {
  const Spheres& s = union_.spheres();
  for (int k = 0; k < static_cast<int>(s.size()); ++k) {
    if (k == a || k == b || k == c) continue;
    if ((q - s[k].center).norm() < s[k].radius - tol_) return false;
  }
  return true;
}

double SphereUnionSurface::surface_distance(const Eigen::Vector3d& p) const {
  const Spheres& s = union_.spheres();
  double outside = std::numeric_limits<double>::infinity();
  for (const Sphere& sp : s) outside = std::min(outside, (p - sp.center).norm() - sp.radius);
  if (outside >= 0) return outside;
  // Inside: the nearest boundary point is the nearest point of a sphere patch, of an arc of an
  // intersection circle, or a triple point — whichever of those candidates is on the boundary.
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < static_cast<int>(s.size()); ++i) {
    const Eigen::Vector3d d = p - s[i].center;
    const double len = d.norm();
    if (len <= 0) continue;
    const Eigen::Vector3d q = s[i].center + (s[i].radius / len) * d;
    if (on_boundary(q, i, -1, -1)) best = std::min(best, (q - p).norm());
  }
  for (const Circle& c : circles_) {
    Eigen::Vector3d w = p - c.center;
    w -= w.dot(c.normal) * c.normal;
    const double len = w.norm();
    if (len <= 0) continue;
    const Eigen::Vector3d q = c.center + (c.radius / len) * w;
    if (on_boundary(q, c.i, c.j, -1)) best = std::min(best, (q - p).norm());
  }
  for (const Eigen::Vector3d& v : vertices_) best = std::min(best, (v - p).norm());
  return std::isfinite(best) ? best : -outside;
}

bool SphereUnionSurface::escapes(const Eigen::Vector3d& q, int i) const {
  const Spheres& s = union_.spheres();
  const Eigen::Vector3d nrm = (q - s[i].center) / s[i].radius;
  const Eigen::Vector3d p = q + 1e3 * tol_ * nrm;  // just outside, clear of round-off
  auto free = [&](const Eigen::Vector3d& d) {
    for (const Sphere& sp : s) {
      const Eigen::Vector3d w = sp.center - p;
      const double tc = w.dot(d);
      if (tc > 0 && w.squaredNorm() - tc * tc < sp.radius * sp.radius) return false;
    }
    return true;
  };
  if (free(nrm)) return true;
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        const Eigen::Vector3d d = Eigen::Vector3d(dx, dy, dz).normalized();
        if (d.dot(nrm) > 0 && free(d)) return true;
      }
  return false;
}

std::vector<Eigen::Vector3d> SphereUnionSurface::sample_surface(std::size_t n,
                                                                std::uint64_t seed) const {
  return sample(n, seed, false, nullptr);
}

std::vector<Eigen::Vector3d> SphereUnionSurface::sample_outer_surface(std::size_t n,
                                                                      std::uint64_t seed,
                                                                      std::size_t* dropped) const {
  return sample(n, seed, true, dropped);
}

std::vector<Eigen::Vector3d> SphereUnionSurface::sample(std::size_t n, std::uint64_t seed,
                                                        bool outer, std::size_t* dropped) const {
  const Spheres& s = union_.spheres();
  std::vector<double> cdf;
  double total = 0.0;
  for (const Sphere& sp : s) cdf.push_back(total += sp.radius * sp.radius);
  SplitMix rng(seed);
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(n);
  // Uniform on the sum of sphere areas, keeping the points no other sphere covers: uniform on
  // the boundary. The boundary is never empty, but bound the work all the same.
  const std::size_t max_tries = 1000 * n + 1000;
  std::size_t lost = 0;
  for (std::size_t tries = 0; pts.size() < n && tries < max_tries; ++tries) {
    const double a = rng.uniform() * total;
    const int i = static_cast<int>(std::min<std::size_t>(
        std::upper_bound(cdf.begin(), cdf.end(), a) - cdf.begin(), s.size() - 1));
    const Eigen::Vector3d q = s[i].center + s[i].radius * unit_direction(rng);
    if (!on_boundary(q, i, -1, -1)) continue;
    if (outer && !escapes(q, i)) {
      ++lost;
      continue;
    }
    pts.push_back(q);
  }
  if (dropped) *dropped = lost;
  return pts;
}

}  // namespace clumpkit
