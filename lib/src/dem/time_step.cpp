#include "clumpkit/dem/time_step.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace clumpkit::dem {

double rayleigh_time(double radius, double density, double shear_modulus, double poisson) {
  return std::numbers::pi * radius * std::sqrt(density / shear_modulus) /
         (0.1631 * poisson + 0.8766);
}

double hertz_max_overlap(double e_star, double r_star, double m_star, double speed) {
  return std::pow(15.0 * m_star * speed * speed / (16.0 * e_star * std::sqrt(r_star)), 0.4);
}

double hertz_contact_time(double e_star, double r_star, double m_star, double speed) {
  // t_c = 2 (δmax / v) ∫_0^1 dx / √(1 − x^(5/2)) = 2.9432 δmax / v.
  return 2.94320 * hertz_max_overlap(e_star, r_star, m_star, speed) / speed;
}

namespace {

// Evenly spread unit directions (Fibonacci sphere).
Eigen::Vector3d direction(int i, int n) {
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  const double z = 1.0 - (2.0 * i + 1.0) / n;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {r * std::cos(golden * i), r * std::sin(golden * i), z};
}

// A uniformly random rotation from raw generator bits (the same on every platform).
Eigen::Quaterniond rotation(std::mt19937_64& g) {
  auto u = [&g] { return static_cast<double>(g() >> 11) * 0x1.0p-53; };
  const double u1 = u(), u2 = 2 * std::numbers::pi * u(), u3 = 2 * std::numbers::pi * u();
  return Eigen::Quaterniond(std::sqrt(1 - u1) * std::sin(u2), std::sqrt(1 - u1) * std::cos(u2),
                            std::sqrt(u1) * std::sin(u3), std::sqrt(u1) * std::cos(u3))
      .normalized();
}

}  // namespace

namespace {

// Largest eigenvalue of M^-1 K for a rigid body (mass m, principal moments I) with unit
// normal springs along n_k and tangential springs of stiffness kt at the points p_k (body
// frame, relative to the centre of mass), 1/kg.
double stiffest_mode(const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector3d>& normals, const ClumpInertia& m,
                     double kt) {
  Eigen::Matrix<double, 6, 6> k = Eigen::Matrix<double, 6, 6>::Zero();
  auto add = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& d, double stiffness) {
    Eigen::Matrix<double, 6, 1> j;
    j.head<3>() = d;
    j.tail<3>() = p.cross(d);
    k += stiffness * j * j.transpose();
  };
  for (size_t c = 0; c < points.size(); ++c) {
    const Eigen::Vector3d& n = normals[c];
    const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
    add(points[c], n, 1.0);
    add(points[c], t1, kt);
    add(points[c], t2, kt);
  }
  Eigen::Matrix<double, 6, 1> s;  // M^-1/2
  s.head<3>().setConstant(1.0 / std::sqrt(m.mass));
  s.tail<3>() = m.inertia.cwiseSqrt().cwiseInverse();
  const Eigen::Matrix<double, 6, 6> a = s.asDiagonal() * k * s.asDiagonal();
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>(a, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .maxCoeff();
}

}  // namespace

double wall_contact_mass(const SphereSet& c, const ClumpInertia& m, double tangential_ratio,
                         double overlap_fraction, int samples) {
  double lambda = 0.0;
  std::vector<Eigen::Vector3d> pts, nrm;
  for (int s = -6; s < samples; ++s) {
    const Eigen::Vector3d n =
        s < 0 ? Eigen::Vector3d(Eigen::Vector3d::Unit((s + 6) / 2) * ((s + 6) % 2 ? -1.0 : 1.0))
              : direction(s, samples);
    double h_max = -1e300;
    for (size_t i = 0; i < c.centers.size(); ++i)
      h_max = std::max(h_max, c.centers[i].dot(n) + c.radii[i]);
    pts.clear(), nrm.clear();
    for (size_t i = 0; i < c.centers.size(); ++i)
      if (c.centers[i].dot(n) + c.radii[i] >= h_max - overlap_fraction * c.radii[i]) {
        pts.push_back(c.centers[i] + c.radii[i] * n);
        nrm.push_back(n);
      }
    lambda = std::max(lambda, stiffest_mode(pts, nrm, m, tangential_ratio));
  }
  return lambda > 0.0 ? 1.0 / lambda : m.mass;
}

double clump_contact_mass(const SphereSet& a, const ClumpInertia& ma, const SphereSet& b,
                          const ClumpInertia& mb, double tangential_ratio, double overlap_fraction,
                          int samples) {
  if (a.centers.empty() || b.centers.empty()) return 0.0;
  std::mt19937_64 gen(0x5eed);
  std::vector<Eigen::Vector3d> bc(b.centers.size());
  std::vector<Eigen::Vector3d> pa, na, pb, nb;
  double inv = 0.0;
  for (int s = 0; s < samples; ++s) {
    const Eigen::Vector3d n = direction(s, samples);
    const Eigen::Quaterniond q = rotation(gen);
    for (size_t j = 0; j < bc.size(); ++j) bc[j] = q * b.centers[j];
    double first = -1e300, r_small = 1e300;
    for (size_t i = 0; i < a.centers.size(); ++i)
      for (size_t j = 0; j < bc.size(); ++j) {
        const Eigen::Vector3d p = a.centers[i] - bc[j];
        const double rr = a.radii[i] + b.radii[j], pn = p.dot(n);
        const double disc = pn * pn - p.squaredNorm() + rr * rr;
        if (disc >= 0) first = std::max(first, pn + std::sqrt(disc));
        r_small = std::min({r_small, a.radii[i], b.radii[j]});
      }
    const double d = first - overlap_fraction * r_small;
    pa.clear(), na.clear(), pb.clear(), nb.clear();
    const Eigen::Quaterniond qi = q.inverse();
    for (size_t i = 0; i < a.centers.size(); ++i)
      for (size_t j = 0; j < bc.size(); ++j) {
        const Eigen::Vector3d bj = bc[j] + d * n;  // b's sphere, a's frame
        const Eigen::Vector3d ab = bj - a.centers[i];
        const double rr = a.radii[i] + b.radii[j];
        if (ab.squaredNorm() >= rr * rr || ab.squaredNorm() == 0.0) continue;
        const Eigen::Vector3d u = ab.normalized();  // from a's sphere towards b's
        pa.push_back(a.centers[i] + a.radii[i] * u);
        na.push_back(u);
        // In b's body frame: its sphere centre, and the normal pointing back at a.
        pb.push_back(b.centers[j] - b.radii[j] * (qi * u));
        nb.push_back(-(qi * u));
      }
    if (pa.empty()) continue;
    inv = std::max(inv, stiffest_mode(pa, na, ma, tangential_ratio) +
                            stiffest_mode(pb, nb, mb, tangential_ratio));
  }
  return inv > 0.0 ? 1.0 / inv : ma.mass * mb.mass / (ma.mass + mb.mass);
}

}  // namespace clumpkit::dem
