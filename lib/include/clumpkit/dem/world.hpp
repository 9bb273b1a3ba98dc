#pragma once
/// The bundled DEM runner: rigid multi-sphere clumps, Hertz–Mindlin contacts, moving triangle
/// walls. Build a World from WorldSettings (validated once, InputError on bad input), then call
/// step() or run_until(). SI units throughout; world frame z up unless gravity says otherwise.
///
/// Per-instance state is stored as arrays (structure of arrays). Angular velocity is stored in
/// the clump's principal (body) frame; omega_world() converts. Positions are centres of mass.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "clumpkit/core/materials.hpp"
#include "clumpkit/dem/contact_law.hpp"
#include "clumpkit/dem/factory.hpp"
#include "clumpkit/dem/profile.hpp"
#include "clumpkit/dem/wall.hpp"
#include "clumpkit/geometry/clump_template.hpp"

namespace clumpkit::dem {

/// A clump type: the template's spheres and union mass properties, shared by every instance.
/// The template must be in (or is moved to) its centroid-principal frame; its mass is used as
/// given (the mass basis is the template's choice, see SPEC §2).
struct ClumpTypeSettings {
  std::string name;
  ClumpTemplate clump;
  std::string material = "pill";
};

/// Replaces the library's contact law for one material pair (order of a, b irrelevant).
struct PairContactOverride {
  std::string material_a, material_b;
  PairContact law;
};

/// The default gate of WorldSettings::implicit_damping (normal dashpots; docs/dem.md,
/// implicit damping).
inline constexpr double kImplicitDampingGate = 0.5;
/// The tangential dashpots' gate relative to the normal ones' (WorldSettings::implicit_damping):
/// the tangential damping uses the extrapolated velocity alone, whose pure-dashpot limit is
/// Γ dt = 1, the normal impulse is telescoped, limit about 0.65 (docs/dem.md).
inline constexpr double kTangentialGate = 1.6;

/// Changes whenever the engine gives different results for the same input (caches of rig
/// results key on it): 2 = session 10's implicit damping and the time step it allows; 3 =
/// session 50's pinch release, which takes only clumps held against a moving wall; 4 = session
/// 51's, which takes the clumps a moving wall loads through the clumps they touch.
inline constexpr int kPhysicsRevision = 4;

struct WorldSettings {
  /// Where the settings came from (scene file), used in InputError messages.
  std::string source = "world settings";
  MaterialLibrary materials = MaterialLibrary::paper_table1();
  /// Pairs without an override use PairContact::from(library interaction, rolling_model).
  RollingModel rolling_model = RollingModel::kStandard;
  std::vector<PairContactOverride> pair_contacts;
  std::vector<ClumpTypeSettings> clump_types;
  std::vector<WallSettings> walls;
  std::vector<FactorySettings> factories;
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};  ///< m/s^2

  double time_step = 0.0;          ///< s; 0 = rayleigh_fraction × T_R of the smallest sphere
  double rayleigh_fraction = 0.2;  ///< used when time_step = 0; a warning above 0.4
  /// Largest impact speed expected (m/s): the Hertz contact time at this speed should span at
  /// least 10 steps (InputError below 4, warning below 10). At 0.2 T_R a 2 m/s pill-pill
  /// impact spans about 14 steps.
  double max_impact_speed = 2.0;
  /// Implicit damping gate (docs/dem.md, "Implicit damping"). Each step, a clump's dashpot
  /// loads L_n = Σ c_n (1/m + |r × n|²/I_min) and L_t = Σ c_t (1/m + |r|²/I_min) over its
  /// contacts (pair contacts twice) bound how fast its contacts' damping acts; the engine's
  /// explicit scheme overshoots above about 0.65/step (normal) and 1/step (tangential), and a
  /// discharge run blew up with a single gate of 1 on max(c_n, c_t). A clump with L_n dt above
  /// this gate or L_t dt above kTangentialGate times it has its damping integrated implicitly
  /// in its own velocity (F_eff = M (M + w dt C)^-1 F, w in [1, 2), neighbours explicit), which
  /// is stable for any step, so the default time step is no longer cut to the damping rate of the
  /// stiffest contact mode (a jammed pill), only to a single contact's. Clumps below the gate are
  /// untouched (bit-identical). 0 = off: the default step then keeps the stiffest mode's rate
  /// below 1/step and a step above 2/rate is refused (as before session 10). In [0, 2].
  double implicit_damping = kImplicitDampingGate;
  double skin = 0.0;  ///< Verlet skin, m; 0 = 0.3 × smallest sphere radius
  /// Where the displacement bound (the two clumps that moved most could have closed the skin)
  /// asks for a neighbour rebuild, first search the last rebuild's cells for a touching pair
  /// the list lacks, and rebuild only if there is one. Off: rebuild at the bound. The
  /// trajectory is the same bits either way; only the number of rebuilds differs.
  bool neighbour_search = true;
  /// OpenMP threads; 0 = auto: all cores from 20 000 spheres on, one thread below (see
  /// docs/dem.md). Results are bit-identical for any thread count.
  int threads = 0;
  std::uint64_t seed = 1;  ///< factories' random stream

  /// Blow-up detection: checked every `check_interval` steps.
  int check_interval = 50;
  double max_speed = 50.0;  ///< m/s; a clump faster than this is a blow-up
  /// Pinch release, a fraction of a sphere radius in [0, 0.5); 0 = off. A prescribed wall
  /// has unlimited force: a pill caught between a moving wall and a fixed one (a vane tip
  /// passing the throat edge, a scraper at the rim) is squeezed without limit, and the run
  /// would stop at the 50 % overlap check. With a release set, a clump loaded by a wall that
  /// moves now (it touches one, or touches a clump so loaded) whose overlap with a wall or
  /// another clump exceeds it is taken out of the run instead (a real pill would break or be
  /// pushed aside), with the clump it is squeezed against, and counted by
  /// World::pinched_count() / pinched_mass(); the first one is a warning. A deep contact among
  /// clumps no moving wall loads (a hard landing while the walls rest) is not released: the
  /// overlap check judges it.
  double pinch_release = 0.0;
};

/// One wall's kinematic state and the load it carries (from the last force evaluation).
struct WallState {
  WallPose pose;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   ///< exerted by the particles, N
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();  ///< about the torque reference point, N m
  Eigen::Vector3d torque_reference = Eigen::Vector3d::Zero();  ///< current, m
};

/// A sub-sphere contact, for diagnostics (coordination number, force chains).
struct ContactInfo {
  int clump_i = -1;
  int clump_j = -1;        ///< −1 for a wall contact
  int wall = -1;           ///< wall index for a wall contact
  Eigen::Vector3d point;   ///< m
  Eigen::Vector3d normal;  ///< unit, from j (or the wall) to i
  double overlap = 0.0;    ///< m
  Eigen::Vector3d force;   ///< on i, N
};

class World {
 public:
  /// Validates everything (materials, pair laws, templates, meshes, motions, factories, time
  /// step) and throws InputError naming settings.source and the field on bad input.
  [[nodiscard]] static World create(WorldSettings settings);

  World(World&&) noexcept;
  World& operator=(World&&) noexcept;
  ~World();

  /// One time step: integrate (first half) → walls move → insert → neighbour update → contact
  /// detection → forces → integrate (second half) → checks. Throws NumericalError with a
  /// diagnosis on blow-up, InputError when a rate factory cannot keep up.
  void step();
  /// Steps until time() >= t (at most one step past).
  void run_until(double t);

  double time() const;
  long step_count() const;
  double dt() const;
  /// Warnings raised at creation or while running (time step, factories), in order.
  const std::vector<std::string>& warnings() const;
  /// Clumps taken out by the pinch release (WorldSettings::pinch_release) and their mass, kg.
  int pinched_count() const;
  double pinched_mass() const;
  const Profile& profile() const;
  Profile& profile();
  const WorldSettings& settings() const;

  // Clump types and instances.
  int clump_type_count() const;
  int clump_type_index(const std::string& name) const;  ///< InputError if unknown
  const ClumpTypeSettings& clump_type(int t) const;
  double clump_type_mass(int t) const;
  Eigen::Vector3d clump_type_inertia(int t) const;  ///< principal moments, kg m^2

  /// Adds a clump (centre of mass x, orientation q: body → world, velocity v, world angular
  /// velocity w). Returns its index. Does not check overlaps.
  int add_clump(int type, const Eigen::Vector3d& x,
                const Eigen::Quaterniond& q = Eigen::Quaterniond::Identity(),
                const Eigen::Vector3d& v = Eigen::Vector3d::Zero(),
                const Eigen::Vector3d& w = Eigen::Vector3d::Zero());

  /// Removes every clump for which `remove(c)` is true (outlets, strike-off, particles that left
  /// the domain); the others keep their order, state and contact histories. Indices of later
  /// clumps shift down. Returns the number removed.
  int remove_clumps(const std::function<bool(int)>& remove);

  int clump_count() const;
  long sphere_count() const;
  int clump_type_of(int c) const;
  double clump_mass(int c) const;
  const std::vector<Eigen::Vector3d>& positions() const;        ///< centres of mass, m
  const std::vector<Eigen::Quaterniond>& orientations() const;  ///< body → world
  const std::vector<Eigen::Vector3d>& velocities() const;       ///< m/s
  const std::vector<Eigen::Vector3d>& omegas_body() const;      ///< rad/s, principal frame
  Eigen::Vector3d omega_world(int c) const;                     ///< rad/s
  /// Changes by hand count as an energy source in the blow-up check.
  void set_velocity(int c, const Eigen::Vector3d& v);
  void set_omega_world(int c, const Eigen::Vector3d& w);
  /// Net contact force / torque on each clump from the last evaluation (no gravity), world frame.
  const std::vector<Eigen::Vector3d>& contact_forces() const;
  const std::vector<Eigen::Vector3d>& contact_torques() const;
  /// World positions and radii of all sub-spheres (updated every step), and their clump ids.
  const std::vector<Eigen::Vector3d>& sphere_positions() const;
  const std::vector<double>& sphere_radii() const;
  const std::vector<int>& sphere_clumps() const;

  // Walls.
  int wall_count() const;
  int wall_index(const std::string& name) const;  ///< InputError if unknown
  const WallSettings& wall_settings(int w) const;
  const WallState& wall(int w) const;
  /// Current world vertices of wall w.
  const std::vector<Eigen::Vector3d>& wall_vertices(int w) const;
  /// Replaces wall w's prescribed motion from now on (times in the motion are world times, so a
  /// motion that starts at time() or later continues the wall's current pose without a jump
  /// when the old motion had ended). Clumps, contact histories and the time are kept: this is how
  /// a rig starts a scraper, a lift or a wheel once the bed has settled. Saved in checkpoints.
  /// InputError on an invalid motion or wall index.
  void set_wall_motion(int w, const WallMotion& motion);

  // Factories.
  /// Adds a factory while running (a rig's second pour once the first has filled its
  /// container), starting at its start_time, which must be time() or later (its first batch
  /// runs at the first step ending at or after it). Its random stream is the one it would have
  /// had as the next entry of the settings' factories, so a World created with it appended to
  /// its settings loads the checkpoints taken after this call and runs on bit-identically (and
  /// is the same state from the call on when start_time > time()). InputError on invalid
  /// settings, naming factories[index].
  void add_factory(const FactorySettings& f);
  int factory_count() const;
  const FactoryStatus& factory_status(int f) const;
  bool factories_done() const;

  // Contacts and energy.
  /// Active sub-sphere contacts after the last force evaluation, in a fixed order.
  std::vector<ContactInfo> contacts() const;
  int contact_count() const;
  double kinetic_energy() const;    ///< J, translational + rotational
  double potential_energy() const;  ///< J, −Σ m g·x
  double elastic_energy() const;    ///< J, stored in the contact springs (last evaluation)
  double total_mass() const;        ///< kg

  /// FNV-1a over the full dynamic state (time, positions, orientations, velocities, contact
  /// histories, wall poses, factory progress). Equal hashes = bit-identical states.
  std::uint64_t state_hash() const;

  /// The full state, including contact histories and factory random streams. Loading requires
  /// a World created from the same settings (a fingerprint is checked: InputError otherwise).
  void save_checkpoint(const std::filesystem::path& path) const;
  void load_checkpoint(const std::filesystem::path& path);

  /// The contact law in force for a material pair, resolved.
  const ResolvedContact& resolved_contact(const std::string& a, const std::string& b) const;

  struct Impl;

 private:
  explicit World(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace clumpkit::dem
