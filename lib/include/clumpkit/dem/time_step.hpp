#pragma once
/// Time-step estimates (SPEC §6).
#include <Eigen/Core>
#include <vector>

namespace clumpkit::dem {

/// Rayleigh wave time of a sphere, T_R = π R √(ρ/G) / (0.1631 ν + 0.8766), s.
double rayleigh_time(double radius, double density, double shear_modulus, double poisson);

/// Maximum overlap of an undamped Hertz impact at relative normal speed v, m:
/// δ_max = (15 m* v² / (16 E* √R*))^(2/5).
double hertz_max_overlap(double e_star, double r_star, double m_star, double speed);

/// Duration of an undamped Hertz impact, s: t_c = 2.9432 δ_max / v.
double hertz_contact_time(double e_star, double r_star, double m_star, double speed);

/// A clump's spheres: centres (body frame, m) and radii (m).
struct SphereSet {
  std::vector<Eigen::Vector3d> centers;
  std::vector<double> radii;
};

/// A clump's mass properties in its principal frame (centres in `SphereSet` relative to the
/// centre of mass, principal axes as coordinate axes).
struct ClumpInertia {
  double mass = 0.0;                                  ///< kg
  Eigen::Vector3d inertia = Eigen::Vector3d::Zero();  ///< principal moments, kg m²
};

/// Equivalent mass of the stiffest contact mode of a clump pressed on a flat wall, kg.
/// Over `samples` approach directions (and the body axes), the spheres within `overlap_fraction`
/// of their radius of the first touch carry unit normal springs and tangential springs of
/// weight `tangential_ratio` (0: normal springs only, for the stiffness limit; √(k_t/k_n) for the
/// dashpots of the damping limit), acting at their contact points on the rigid clump. The largest
/// eigenvalue λ of M^-1 K (M = diag(m, m, m, I)) is the squared frequency of the fastest mode per
/// unit spring: 1/λ is the mass a single Hertz spring would need to ring as fast. It is m/N for N
/// spheres touching together (a Hertz impact on N springs in parallel lasts N^(-2/5) as long), and
/// smaller again when the contacts can rock or twist the clump about its centre: a pill flat on its
/// face rocks about √2 times faster than it bounces. The default time step makes a Hertz impact of
/// this mass last 10 steps and keeps the contact damping's rate on the dashpot equivalent mass
/// below 1/step (World::create, docs/dem.md): above about 2/step the explicit damping of a jammed
/// pill grows without bound.
double wall_contact_mass(const SphereSet& clump, const ClumpInertia& m,
                         double tangential_ratio = 0.8, double overlap_fraction = 0.05,
                         int samples = 256);

/// The same for two clumps pressed together: over `samples` approach directions and relative
/// orientations (deterministic), the sphere pairs in contact when clump b has moved
/// `overlap_fraction` of the smaller radius past its first touch of clump a; 1/m_eq = λ_a + λ_b,
/// each body's stiffest mode under the contacts of the pair (a bound: the two modes need not
/// coincide), kg.
double clump_contact_mass(const SphereSet& a, const ClumpInertia& ma, const SphereSet& b,
                          const ClumpInertia& mb, double tangential_ratio = 0.8,
                          double overlap_fraction = 0.05, int samples = 256);

}  // namespace clumpkit::dem
