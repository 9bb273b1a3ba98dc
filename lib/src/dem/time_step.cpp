#include "clumpkit/dem/time_step.hpp"

#include <cmath>
#include <numbers>

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

}  // namespace clumpkit::dem
