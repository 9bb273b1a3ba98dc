#pragma once
/// What the three rigs share (rig.cpp runs them; bulk_density.cpp, angle_of_repose.cpp and
/// discharge.cpp each follow the paper's procedure): one repeat's context, the engine settings
/// of a rig, the pour, settling by the kinetic-energy criterion, the checkpoints that make a
/// killed repeat resumable, and the hand-over from the pour (phase 1) to the rig's action
/// (phase 2).
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "clumpkit/dem/world.hpp"
#include "clumpkit/geometry/sphere.hpp"
#include "clumpkit/rigs/geometry.hpp"
#include "clumpkit/rigs/heap_angle.hpp"
#include "clumpkit/rigs/rig.hpp"

namespace clumpkit::rigs::detail {

using Clock = std::chrono::steady_clock;

/// Sphere-steps are counted at every settle/action check (the sphere count changes as pills are
/// poured and removed).
struct Meter {
  double sphere_steps = 0.0;
  long last_steps = 0;
  void tick(const dem::World& w) {
    sphere_steps += double(w.step_count() - last_steps) * double(w.sphere_count());
    last_steps = w.step_count();
  }
};

/// One repeat of a rig.
struct Ctx {
  const RigRequest& req;
  ScaleParams p;
  std::vector<dem::ClumpTypeSettings> types;  // filled once per run
  std::filesystem::path dir;                  // this repeat's folder, may be empty
  std::uint64_t seed = 1;
  int repeat = 0;
  Clock::time_point last_checkpoint = Clock::now();
  Clock::time_point last_progress = Clock::now();
  // Clumps whose centre satisfies `outside` have left the rig for good (overflow, discharge,
  // fallen off the plate): removed from the World; `removed_mass` totals them (a settle's
  // checkpoint keeps the total; phase 2 starts it again from 0, see discharge).
  std::function<bool(const Eigen::Vector3d&)> outside = nullptr;
  double removed_mass = 0.0;
  Meter meter = {};

  void say(const std::string& s) const {
    if (req.progress) req.progress(fmt::format("[{} repeat {}] {}", req.rig, repeat + 1, s));
  }
  // A progress line at most every RigRequest::progress_every (5 s) of wall time on the long
  // loops (pour, strike-off, lift, discharge); `line` is formatted only when one is due.
  template <class F>
  void progress(F&& line) {
    if (std::chrono::duration<double>(Clock::now() - last_progress).count() <= req.progress_every &&
        req.progress_every > 0.0)
      return;
    say(line());
    last_progress = Clock::now();
  }
};

/// The rigs' procedures, one repeat each (SPEC §7): pour, settle, the rig's action, measure.
RepeatResult bulk_density(Ctx& c);
RepeatResult angle_of_repose(Ctx& c);
RepeatResult discharge(Ctx& c);
/// The same procedures written as a LIGGGHTS deck and run there (liggghts_rigs.cpp): bulk
/// density and angle of repose.
RepeatResult liggghts_repeat(Ctx& c);

/// The bulk-density rig's scene, shared by both engines: the cup, the catch plate below it, the
/// pour above the rim and the scraper waiting beside the cup (wall `scraper_wall`, at rest).
struct BulkDensityScene {
  CupGeometry cup;
  dem::WorldSettings ws;
  int scraper_wall = -1;
  double pour_mass = 0.0;             ///< kg
  double x_start = 0.0, x_end = 0.0;  ///< m, the blade's travel along x
  double clearance = 0.0;             ///< m, blade above the rim
  double scraper_speed = 0.0;         ///< m/s
  std::string scraper_material;
  /// The scraper moving from x_start to x_end from `t_on` (s).
  dem::WallSettings scraper(double t_on) const;
};
BulkDensityScene bulk_density_scene(const Ctx& c);
/// What the cup holds: the clumps whose centre lies inside it (as the lab weighs it after the
/// strike-off).
struct CupWeight {
  double mass = 0.0;  ///< kg
  long pills = 0;
};
CupWeight weigh_cup(const std::vector<Eigen::Vector3d>& centres, const std::vector<double>& masses,
                    const CupGeometry& cup);

/// The angle-of-repose rig's scene, shared by both engines: the plate, the tube standing on it
/// (wall `tube_wall`, at rest) and the column fill.
struct AngleOfReposeScene {
  const Ctx* c = nullptr;
  LiftingGeometry g;
  dem::WorldSettings ws;
  int tube_wall = -1;
  double br = 0.0;  ///< m, the pills' largest bounding radius
  /// The tube rising at the lift speed from t_on to t_off (s).
  dem::WallSettings tube(double t_on, double t_off) const;
  /// The pour from above the tube's top of what the column could not hold.
  dem::FactorySettings top_up(double t_start, double mass) const;
};
/// Throws InputError when the tube cannot hold the scale's heap mass.
AngleOfReposeScene angle_of_repose_scene(const Ctx& c);
/// The angle-of-repose observables of a measured heap, and the measurement's details.
RepeatResult heap_result(const HeapAngle& h);

/// The discharger's scene, shared by both engines: housing, hopper, end plates, the catch plate
/// below the outlet (clumps below `z_out` have left the rig), the wheel (wall `wheel_wall`, at
/// rest) and the hopper fill.
struct DischargeScene {
  const Ctx* c = nullptr;
  WheelGeometry g;
  dem::WorldSettings ws;
  int wheel_wall = -1;
  double z_out = 0.0;  ///< m
  /// The wheel turning at the scale's rpm from `t_on` (s).
  dem::WallSettings wheel(double t_on) const;
};
/// Throws InputError for a slice narrower than a pill or a bed the hopper cannot hold.
DischargeScene discharge_scene(const Ctx& c);
/// When the counted pockets close, for a wheel started at t0 (s): pocket k lies between vanes k
/// and k+1 and closes when its upper vane passes below the throat edge; it is weighed
/// `settle_delay` later. `t_end` is when the last counted pocket is weighed.
struct PocketSchedule {
  double omega = 0.0, pitch = 0.0, period = 0.0;  ///< rad/s, rad, s
  double settle_delay = 0.0, t_end = 0.0;         ///< s
  struct Pocket {
    double t_close;  ///< s
    int k;
  };
  std::vector<Pocket> pockets;  ///< the skipped and measured pockets, in closing order
};
PocketSchedule pocket_schedule(const WheelGeometry& g, const ScaleParams& p, double t0);
/// The mass of the clumps whose centre lies in the pocket whose lower vane is at angle `lower`
/// (rad, from +x towards +z), kg.
double pocket_mass(const std::vector<Eigen::Vector3d>& centres, const std::vector<double>& masses,
                   const WheelGeometry& g, double lower);
/// The discharge observables from the counted pockets' fills (kg in the slice) and the
/// discharged mass over time (s, kg).
RepeatResult discharge_result(const ScaleParams& p, const WheelGeometry& g,
                              const std::vector<double>& fills, const std::vector<double>& curve_t,
                              const std::vector<double>& curve_m);
/// Null, or why the counted pockets' fills (kg, in closing order) look like a jammed wheel: no
/// pocket received a pill, or a pocket has under a quarter of the fullest one's mass (numbered
/// from 1). In the result's details as `jam`.
nlohmann::json discharge_jam(const std::vector<double>& fills);

/// One repeat through `run`, run again while its result carries the jam flag (discharge_jam),
/// as a lab clears the rig and runs again: from a fresh fill with the seed + kJamSeedStep ×
/// attempt, in the repeat's folder's retry_A/ (A = 1, 2, ...), kJamAttempts in all. A result
/// after a jam lists the jammed attempts in its details (`jammed`: seed and why) and the seed
/// that flowed (`seed_used`). Every attempt jammed: NumericalError naming the seeds (the
/// pockets starved, so the values stand for no flow of the model). With --bed-from the bed is
/// given and a jam is kept, flagged, not run again.
RepeatResult run_attempts(Ctx& c, const std::function<RepeatResult(Ctx&)>& run);

/// The engine settings every rig starts from: the model's materials (stiffness scaled by the
/// scale), clump types and contact laws against `wall_materials`, the scale's step and damping.
dem::WorldSettings base_settings(const Ctx& c, const std::vector<std::string>& wall_materials);
/// The model's mean density of the sphere unions, kg/m^3, weighted by the mixture's fractions.
double mean_union_density(const Ctx& c);
/// The largest distance of a sphere's surface from its clump's centre, m.
double max_bound_radius(const Ctx& c);
/// A factory pouring `mass` into `region`: all at once when the region can hold it at a loose
/// 20 % solid fraction, else at the scale's pour rate or as fast as the region can take pills,
/// whichever is slower (the small scale's cup asked more of its pour region per batch than
/// random insertion could place, and the factory stopped the run as falling behind).
dem::FactorySettings pour(const Ctx& c, const dem::Region& region, double mass);
/// The engine checkpoint and the rig's state (state.json: phase, lift end, pocket fills, ...) are
/// one commit: the checkpoint goes to a new file named by phase and step, then state.json names
/// it (atomic rename), then older checkpoints are deleted. A kill at any moment leaves a
/// state.json and the checkpoint it names, taken at the same step. (Writing both under fixed
/// names let a kill between the two writes pair a new checkpoint with an old state: a resume in
/// the middle of the angle-of-repose lift then stopped the tube twice, 26.3477° instead of
/// 26.3464°.) Written every RigRequest::checkpoint_interval of wall time, or `now`.
void keep_checkpoint(Ctx& c, dem::World& w, int phase, const nlohmann::json& extra, bool now);
/// RMS clump speed, m/s (from the kinetic energy and the total mass).
double rms_speed(const dem::World& w);
/// The engine's stage profile and throughput, for the JSON and the progress stream.
nlohmann::json profile_json(const Ctx& c, const dem::World& w, double sphere_steps);
/// Pills taken out by the pinch release: said once, and listed in the repeat's details.
nlohmann::json pinch_json(const Ctx& c, const dem::World& w);
/// Removes the clumps that have left the rig (Ctx::outside); returns their mass, kg.
double cull(Ctx& c, dem::World& w);

struct SettleInfo {
  bool settled = false;
  double time = 0.0;     // s simulated in this settle
  double rms_speed = 0;  // m/s at the end
  bool stopped = false;  // ended by `stop` (the factories done, the bed not yet at rest)
};

/// Runs until the factories are done and the RMS clump speed stays below the scale's threshold
/// for 3 checks 10 ms apart, or until settle_max of simulated time after the factories finished
/// (constant-torque rolling friction can keep a few pills creeping: the bed counts as settled
/// then, and the details say so). Resumes its own bookkeeping from a checkpoint taken inside it.
/// `stop`, if given, is asked at each check once the factories are done: true ends the settle
/// there (SettleInfo::stopped; the next pour need not wait for this bed to come to rest).
SettleInfo settle(Ctx& c, dem::World& w, int phase, const nlohmann::json& extra,
                  const std::string& what, const std::function<bool()>& stop = {});
nlohmann::json settle_json(const SettleInfo& s);
/// The World's spheres (positions and radii).
Spheres world_spheres(const dem::World& w);
/// VTK files of the spheres and walls, `name`_*.vtp in the repeat's folder, if asked for.
void snapshot(const Ctx& c, const dem::World& w, const std::string& name);
/// A wall velocity `v` from t_on to t_off (infinite: for ever), with 0.1 ms ramps.
dem::VelocityProfile step_velocity(double t_on, double t_off, const Eigen::Vector3d& v);
/// The repeat's state.json ({"phase": 0} if none or unreadable).
nlohmann::json load_state(const Ctx& c);
/// The repeat's World: created from `ws` (walls at rest), then restored from the checkpoint of
/// the phase the state names, if any (the checkpoint carries the walls' motions).
dem::World open_world(Ctx& c, const dem::WorldSettings& ws, const nlohmann::json& state,
                      const std::string& what);
/// Phase 1: pour and settle.
SettleInfo pour_and_settle(Ctx& c, dem::World& w, const std::string& what,
                           const nlohmann::json& extra = {},
                           const std::function<bool()>& stop = {});
/// Phase 2 begins: the action's wall starts moving in the same World (contact histories kept).
void start_action(Ctx& c, dem::World& w, int wall, const dem::WallMotion& m, nlohmann::json& state);

}  // namespace clumpkit::rigs::detail
