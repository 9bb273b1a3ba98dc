#include "clumpkit/dem/time_step.hpp"

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

int wall_contact_multiplicity(const SphereSet& c, double overlap_fraction, int samples) {
  int best = c.centers.empty() ? 0 : 1;
  // The body axes first: a clump in its principal frame lies flat on a wall along them (a pill
  // on its end face puts a whole ring of spheres down at once).
  for (int s = -6; s < samples; ++s) {
    const Eigen::Vector3d n =
        s < 0 ? Eigen::Vector3d(Eigen::Vector3d::Unit((s + 6) / 2) * ((s + 6) % 2 ? -1.0 : 1.0))
              : direction(s, samples);
    double h_max = -1e300;
    for (size_t i = 0; i < c.centers.size(); ++i)
      h_max = std::max(h_max, c.centers[i].dot(n) + c.radii[i]);
    int k = 0;
    for (size_t i = 0; i < c.centers.size(); ++i)
      if (c.centers[i].dot(n) + c.radii[i] >= h_max - overlap_fraction * c.radii[i]) ++k;
    best = std::max(best, k);
  }
  return best;
}

int clump_contact_multiplicity(const SphereSet& a, const SphereSet& b, double overlap_fraction,
                               int samples) {
  if (a.centers.empty() || b.centers.empty()) return 0;
  std::mt19937_64 gen(0x5eed);
  std::vector<Eigen::Vector3d> bc(b.centers.size());
  int best = 1;
  for (int s = 0; s < samples; ++s) {
    const Eigen::Vector3d n = direction(s, samples);
    const Eigen::Quaterniond q = rotation(gen);
    for (size_t j = 0; j < bc.size(); ++j) bc[j] = q * b.centers[j];
    // Clump b comes in from far along -n (its centre at d n, d decreasing): pair (i, j) first
    // touches at the largest root d of |p - d n| = r_i + r_j, p = c_i - c_j.
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
    int k = 0;
    for (size_t i = 0; i < a.centers.size(); ++i)
      for (size_t j = 0; j < bc.size(); ++j) {
        const double rr = a.radii[i] + b.radii[j];
        if ((a.centers[i] - bc[j] - d * n).squaredNorm() < rr * rr) ++k;
      }
    best = std::max(best, k);
  }
  return best;
}

}  // namespace clumpkit::dem
