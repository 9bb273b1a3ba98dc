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

/// How many spheres of a clump can press on a flat wall at once: over `samples` approach
/// directions, the spheres within `overlap_fraction` of their radius of the first to touch.
/// An impact then loads that many Hertz springs in parallel, so it lasts t_c(one sphere) times
/// N^(-2/5). Clumps of a few heavily overlapping spheres (the paper's A4, B4, C2) have N close to
/// their sphere count and a mass close to one sphere's: their impacts are the shortest.
int wall_contact_multiplicity(const SphereSet& clump, double overlap_fraction = 0.05,
                              int samples = 256);

/// The same for two clumps: over `samples` approach directions and relative orientations
/// (deterministic), the most sphere pairs in contact when clump b has moved `overlap_fraction`
/// of the smaller radius past its first touch of clump a.
int clump_contact_multiplicity(const SphereSet& a, const SphereSet& b,
                               double overlap_fraction = 0.05, int samples = 256);

}  // namespace clumpkit::dem
