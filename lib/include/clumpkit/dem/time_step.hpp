#pragma once
/// Time-step estimates (SPEC §6).
namespace clumpkit::dem {

/// Rayleigh wave time of a sphere, T_R = π R √(ρ/G) / (0.1631 ν + 0.8766), s.
double rayleigh_time(double radius, double density, double shear_modulus, double poisson);

/// Maximum overlap of an undamped Hertz impact at relative normal speed v, m:
/// δ_max = (15 m* v² / (16 E* √R*))^(2/5).
double hertz_max_overlap(double e_star, double r_star, double m_star, double speed);

/// Duration of an undamped Hertz impact, s: t_c = 2.9432 δ_max / v.
double hertz_contact_time(double e_star, double r_star, double m_star, double speed);

}  // namespace clumpkit::dem
