#pragma once
/// The contact law of one material pair: Hertz–Mindlin (no-slip) as in the paper's eqs. (1)–(4)
/// (SPEC §6), built from effects that are either present or absent. An absent effect is not in
/// the physics at all (no spring, no history, no torque); a present effect with a zero value is
/// still evaluated. The calibration module switches effects per pair (SPEC §8).
#include <Eigen/Core>
#include <cmath>
#include <optional>
#include <string>

#include "clumpkit/core/materials.hpp"

namespace clumpkit::dem {

/// How rolling resistance is modelled (SPEC §6).
enum class RollingModel {
  /// Paper eq. (2), EDEM "standard": constant directional torque −μr R |Fn| ω̂ on each clump,
  /// R = radius of the sub-sphere in contact, ω = that clump's own angular velocity. The default.
  kStandard,
  /// LIGGGHTS `rolling_friction cdt` (3.8, rolling_model_cdt.h): −μr R* F_hertz ω_rel/|ω_rel|
  /// with ω_rel = ω_i − ω_j (wall: ω_wall), F_hertz the elastic normal force (no damping), and
  /// the component along the contact normal (twisting) removed.
  kCdt,
  /// Elastic–plastic spring–dashpot, "type C" (Ai et al. 2011): rolling spring
  /// k_r = 2.25 S_n μr² R*², torque capped at μr R* |Fn|, viscous damping off at the cap.
  kEpsd,
  /// (Last, so the earlier values keep their numbers.) EDEM's help text variant of the standard
  /// model: R = distance from the contact point to the
  /// clump's centre of mass (larger than the sub-sphere radius for off-centre spheres).
  kStandardCom,
};

const char* to_string(RollingModel m);
/// "standard", "standard_com", "cdt" or "epsd"; throws InputError(where, field) otherwise.
RollingModel rolling_model_from_string(const std::string& s, const std::string& where = "",
                                       const std::string& field = "");

struct RollingFriction {
  RollingModel model = RollingModel::kStandard;
  double coefficient = 0.0;      ///< μr >= 0, dimensionless
  double viscous_damping = 0.3;  ///< EPSD only: fraction of the critical rolling damping, >= 0
};

/// Simplified JKR (LIGGGHTS `cohesion sjkr`): attractive normal force k A while the spheres
/// overlap, A = 2π R* δ (the area of the overlap circle for small δ).
struct Cohesion {
  double energy_density = 0.0;  ///< k, J/m^3 >= 0
};

/// The effects of one material pair. Every optional is one effect of the SPEC §8 catalogue:
/// restitution (normal and tangential damping), friction (Mindlin spring + Coulomb cap; called
/// particle_friction or wall_friction by pair kind), rolling_friction, cohesion.
struct PairContact {
  std::optional<double> restitution;      ///< e in (0, 1]; absent = undamped (elastic)
  std::optional<double> static_friction;  ///< μs >= 0; absent = no tangential force at all
  std::optional<RollingFriction> rolling;
  std::optional<Cohesion> cohesion;

  /// All effects of a library interaction present (cohesion absent).
  static PairContact from(const Interaction& i, RollingModel model = RollingModel::kStandard);
  /// Throws InputError(where, field + ".restitution" ...) for values out of range.
  void validate(const std::string& where, const std::string& field) const;
};

/// A pair's law with the material constants folded in (what the force loop reads).
struct ResolvedContact {
  double e_star = 0.0;  ///< Pa, Y* = [(1−νi²)/Ei + (1−νj²)/Ej]^−1
  double g_star = 0.0;  ///< Pa, G* = [Σ 2(2−ν)(1+ν)/E]^−1
  bool damping = false;
  double beta = 0.0;  ///< paper's β = −ln e / √(ln² e + π²) >= 0
  bool friction = false;
  double mu_s = 0.0;
  bool rolling = false;
  RollingFriction roll;
  bool cohesion = false;
  double cohesion_k = 0.0;
};

ResolvedContact resolve(const Material& a, const Material& b, const PairContact& law);

/// Geometry and kinematics of one contact, body i against body j (j may be a wall).
struct ContactKinematics {
  Eigen::Vector3d normal;  ///< unit, from j towards i
  double overlap = 0.0;    ///< δ > 0, m
  double r_star = 0.0;     ///< m
  double m_star = 0.0;     ///< kg
  double radius_i = 0.0;   ///< sub-sphere radius of i (standard rolling), m
  double radius_j = 0.0;   ///< of j, 0 for a wall
  double arm_i = 0.0;  ///< distance contact point – centre of mass of clump i (standard_com), m
  double arm_j = 0.0;  ///< of clump j, 0 for a wall
  Eigen::Vector3d v_rel;  ///< velocity of i minus velocity of j at the contact point, m/s
  /// The same relative velocity at the time of the positions, for the damping terms only (the
  /// World passes velocity Verlet's predicted v(t); v_rel is the half-step velocity, which moves
  /// the springs consistently with the positions). Absent = v_rel.
  std::optional<Eigen::Vector3d> v_rel_damping;
  Eigen::Vector3d omega_i;  ///< world angular velocity of clump i, rad/s
  Eigen::Vector3d omega_j;  ///< of clump j or of the wall
};

/// Per-contact state that persists across steps (history springs), world frame.
struct ContactHistory {
  Eigen::Vector3d shear = Eigen::Vector3d::Zero();  ///< tangential spring displacement δt, m
  Eigen::Vector3d roll = Eigen::Vector3d::Zero();   ///< EPSD rolling spring torque, N m
  /// Potential of the normal damping force, Φ(δ) = (4/5) c δ^(5/4) with c δ^(1/4) δ̇ the force
  /// of eq. (3), at the end of the last step's impulse window (t + dt/2), N s. See
  /// evaluate_contact.
  double damping = 0.0;
};

struct ContactForce {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< on i (j gets −force), N
  /// Rolling torque on clump i / j (CDT and EPSD models), N m.
  Eigen::Vector3d torque_i = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_j = Eigen::Vector3d::Zero();
  /// Standard model: magnitude μr R |Fn| of the torque that opposes clump i's / j's own
  /// angular velocity, N m. The integrator applies it along −ω̂ at the moment of the kick (so a
  /// clump at rest stays at rest), limited so that it stops a rotation but never reverses it.
  double roll_i = 0.0;
  double roll_j = 0.0;
  double normal = 0.0;          ///< signed normal force (Hertz + damping + cohesion), N
  double elastic_energy = 0.0;  ///< stored in the springs, minus the cohesive well, J
  /// The dashpots in effect this step, as linear coefficients on the relative velocity, N s/m:
  /// normal c δ^¼ = 2√(5/6) β √(S_n m*), tangential 2√(5/6) β √(S_t m*) while the spring sticks
  /// (0 when sliding, closing, or the effect is absent). The World's implicit damping uses them.
  double dashpot_n = 0.0;
  double dashpot_t = 0.0;
};

/// Evaluates the law for one contact over a step of `dt`, updating the history springs.
///
/// The paper's damping prefactor 2√(5/6): c_n = 2√(5/6) β √(S_n m*), eq. (3).
inline double contact_damping_factor() {
  return 1.8257418583505538;
}

/// The constant c of eq. (3)'s normal dashpot c δ^(1/4): 2√(5/6) β √(2 Y* √R* m*).
inline double normal_dashpot_constant(const ResolvedContact& law, double r_star, double m_star) {
  return contact_damping_factor() * law.beta *
         std::sqrt(2.0 * law.e_star * std::sqrt(r_star) * m_star);
}

/// The tangential dashpot of eq. (4) on a spring of stiffness S_t: 2√(5/6) β √(S_t m*), N s/m.
inline double tangential_dashpot(const ResolvedContact& law, double s_t, double m_star) {
  return contact_damping_factor() * law.beta * std::sqrt(s_t * m_star);
}

/// The normal damping force of eq. (3), c δ^(1/4) δ̇ with c = 2√(5/6) β √(2 Y* √R* m*), is the
/// time derivative of Φ(δ) = (4/5) c δ^(5/4). With dt > 0 it is applied as the impulse
/// Φ(δ(t + dt/2)) − Φ(δ(t − dt/2)) over the step's window, divided by dt: the upper end is
/// predicted from δ and the approach rate at t (v_rel_damping), the lower end is the previous
/// step's upper end (history.damping). The impulses telescope, so over a whole contact the
/// damping impulse sums to exactly what the continuous model gives however the contact's start
/// and end fall between steps; a point evaluation misses most of the first and last (partial)
/// steps, where δ^(1/4) is steep, which made e come out up to 6 % low at the default time step.
/// A contact whose overlap has gone (δ <= 0) with history.damping > 0 is *closing*: it gets the
/// last impulse, −history.damping / dt along the normal, and nothing else. With dt = 0 (the
/// first force evaluation of a run) the damping is evaluated at the point, c δ^(1/4) δ̇.
void evaluate_contact(const ResolvedContact& law, const ContactKinematics& k, double dt,
                      ContactHistory& history, ContactForce& out);

/// Keeps a history vector in the current tangent plane (normal `n`) and its length.
Eigen::Vector3d project_to_tangent(const Eigen::Vector3d& v, const Eigen::Vector3d& n);

}  // namespace clumpkit::dem
