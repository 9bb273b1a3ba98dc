#pragma once
// Analytic solids written for the tests only (ray intervals and exact surface distances), so that
// the sampler and the shape-error analysis can be checked against closed forms.
#include <cmath>
#include <numbers>

#include "clumpkit/raycast/surface_solid.hpp"

namespace clumpkit::test {

/// A ball of radius r centred at c.
class Ball final : public SurfaceSolid {
 public:
  Ball(Eigen::Vector3d c, double r) : c_(c), r_(r) {}
  Eigen::AlignedBox3d bounds() const override {
    return {c_ - Eigen::Vector3d::Constant(r_), c_ + Eigen::Vector3d::Constant(r_)};
  }
  void intervals(const Eigen::Vector3d& o, int axis, IntervalList& out) const override {
    out.clear();
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const double h2 = r_ * r_ - std::pow(o[u] - c_[u], 2) - std::pow(o[v] - c_[v], 2);
    if (h2 > 0) out.push_back({c_[axis] - std::sqrt(h2), c_[axis] + std::sqrt(h2)});
  }
  double surface_distance(const Eigen::Vector3d& p) const override {
    return std::abs((p - c_).norm() - r_);
  }
  std::vector<Eigen::Vector3d> sample_surface(std::size_t n, std::uint64_t seed) const override {
    SplitMix rng(seed);
    std::vector<Eigen::Vector3d> pts;
    for (std::size_t k = 0; k < n; ++k) {
      const double z = 2 * rng.uniform() - 1, phi = 2 * std::numbers::pi * rng.uniform();
      const double s = std::sqrt(1 - z * z);
      pts.push_back(c_ + r_ * Eigen::Vector3d(s * std::cos(phi), s * std::sin(phi), z));
    }
    return pts;
  }

 private:
  Eigen::Vector3d c_;
  double r_;
};

/// A box of edge lengths `size`, rotated by R and centred at c (slab intersection).
class OrientedBox final : public RaySolid {
 public:
  OrientedBox(Eigen::Vector3d size, Eigen::Matrix3d R, Eigen::Vector3d c)
      : h_(0.5 * size), R_(R), c_(c) {}
  Eigen::AlignedBox3d bounds() const override {
    const Eigen::Vector3d e = R_.cwiseAbs() * h_;
    return {c_ - e, c_ + e};
  }
  void intervals(const Eigen::Vector3d& o, int axis, IntervalList& out) const override {
    out.clear();
    Eigen::Vector3d p = o;
    p[axis] = 0;
    // Local frame: x = Rᵀ (p + t e_axis - c).
    const Eigen::Vector3d q = R_.transpose() * (p - c_);
    const Eigen::Vector3d d = R_.transpose().col(axis);
    double t0 = -1e300, t1 = 1e300;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(d[k]) < 1e-300) {
        if (std::abs(q[k]) >= h_[k]) return;
        continue;
      }
      double a = (-h_[k] - q[k]) / d[k], b = (h_[k] - q[k]) / d[k];
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
    }
    if (t0 < t1) out.push_back({t0, t1});
  }

 private:
  Eigen::Vector3d h_;
  Eigen::Matrix3d R_;
  Eigen::Vector3d c_;
};

/// A torus about the z axis through the origin: major radius R, tube radius a.
class Torus final : public RaySolid {
 public:
  Torus(double R, double a) : R_(R), a_(a) {}
  Eigen::AlignedBox3d bounds() const override {
    return {Eigen::Vector3d(-R_ - a_, -R_ - a_, -a_), Eigen::Vector3d(R_ + a_, R_ + a_, a_)};
  }
  void intervals(const Eigen::Vector3d& o, int axis, IntervalList& out) const override {
    out.clear();
    if (axis == 2) {  // (rho - R)^2 + z^2 < a^2
      const double rho = std::hypot(o.x(), o.y());
      const double h2 = a_ * a_ - (rho - R_) * (rho - R_);
      if (h2 > 0) out.push_back({-std::sqrt(h2), std::sqrt(h2)});
      return;
    }
    // Line along x (or y) at transverse w and height z: R - c < sqrt(t^2 + w^2) < R + c.
    const double w = axis == 0 ? o.y() : o.x();
    const double c2 = a_ * a_ - o.z() * o.z();
    if (c2 <= 0) return;
    const double c = std::sqrt(c2);
    const double hi = (R_ + c) * (R_ + c) - w * w;
    if (hi <= 0) return;
    const double lo = (R_ - c) * (R_ - c) - w * w;
    const double th = std::sqrt(hi);
    if (lo <= 0) {
      out.push_back({-th, th});
    } else {
      const double tl = std::sqrt(lo);
      out.push_back({-th, -tl});
      out.push_back({tl, th});
    }
  }

 private:
  double R_, a_;
};

}  // namespace clumpkit::test
