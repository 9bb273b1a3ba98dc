#pragma once
/// The paper's validation rigs run through the bundled DEM engine (SPEC §7): factory → pour →
/// settle → the rig's action → measurement, repeated with different seeds.
///
/// Each repeat runs in two phases in one World (pour and settle; then the action with the
/// settled bed). The action's wall motion starts when the bed has settled
/// (World::set_wall_motion), so contact histories carry over. Clumps that have left the rig
/// (overflow, discharge) are removed as they go. Both phases checkpoint through the engine, so a
/// killed run resumes where it stopped and finished repeats are kept.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "clumpkit/rigs/catalogue.hpp"
#include "clumpkit/rigs/model.hpp"

namespace clumpkit::rigs {

/// Changes whenever a rig gives different results for the same model, settings, scale and seed
/// (caches of rig results key on it, beside dem::kPhysicsRevision). One counter for every rig
/// until session 40: 1 = session 30's 24 mm wheel slice at `tiny` (12 mm arched above the
/// throat); 2 = session 31's angle-of-repose fill when the tube cannot hold the mass (paper
/// scale): the column fill ends once it trickles and the pour from above follows at once; 3 =
/// session 33's paper-scale discharge: a 20 mm slice holding 10 kg per 100 mm, its hopper filled
/// at 1 kg/s per 20 mm (was 100 mm, 10 kg, 0.04 kg/s). Since then each rig has its own
/// (rig_revision), so that a change to one rig keeps the cached runs of the others: this one is
/// now the bulk density's and the angle of repose's.
inline constexpr int kRigsRevision = 3;
/// The discharger's: 4 since session 41 (its pour region cut by the hopper's walls); 5 since
/// session 42 (a jammed wheel is run again from a fresh fill, kJamAttempts in all: only runs
/// that jammed change).
inline constexpr int kDischargeRevision = 5;
/// Attempts of a discharge repeat whose wheel jams (run_rig): the first with the repeat's seed,
/// each further one from a fresh fill with kJamSeedStep more.
inline constexpr int kJamAttempts = 3;
inline constexpr std::uint64_t kJamSeedStep = 1000;
/// The revision of one rig's results: kDischargeRevision for `discharge`, else kRigsRevision.
inline int rig_revision(std::string_view rig) {
  return rig == "discharge" ? kDischargeRevision : kRigsRevision;
}
/// The paper's discharger bed per length of pocket (10 kg in the 100 mm pocket, SPEC §7), kg/m:
/// at paper scale a slice of the wheel holds this times its length.
inline constexpr double kPaperBedPerLength = 100.0;

/// Numbers that size a rig at one scale. Defaults are filled by rig_scale(); every field is
/// reported in the result's JSON so a run documents itself.
struct ScaleParams {
  std::string name;                ///< tiny | mini | small | paper
  double stiffness_scale = 1.0;    ///< factor on every Young's modulus (speed-up, see docs)
  bool implicit_damping = true;    ///< engine implicit damping at its default gate (--set)
  double rayleigh_fraction = 0.2;  ///< time step / Rayleigh time
  double settle_speed = 0.005;     ///< m/s, RMS clump speed below which a bed is at rest
  double settle_max = 2.0;         ///< s of simulated time allowed for one settle
  // bulk_density
  double cup_diameter = 0.070, cup_height = 0.0676;  ///< m
  double pour_rate = 0.5;                            ///< kg/s
  /// Bulk density pour: every pill inside the pour region (true) or only its centre (false,
  /// LIGGGHTS' `all_in no`: more pills per batch from the same region, a faster pour).
  bool pour_whole_in_region = true;
  double scraper_speed = 0.05;  ///< m/s
  // angle_of_repose
  double tube_diameter = 0.0657, tube_height = 0.150;  ///< m
  double plate_side = 0.5;                             ///< m
  double heap_mass = 0.5;                              ///< kg poured into the tube
  double lift_speed = 200.0 / 60000.0;                 ///< m/s
  double lift_height = 0.0;  ///< m the tube rises; 0 = until it clears the bed
  // discharge
  double wheel_scale = 1.0;     ///< factor on the wheel's radii and the hopper (1 = paper)
  double slice_length = 0.100;  ///< m along the wheel axis (paper: 0.1 m pockets)
  double bed_mass = 10.0;       ///< kg in the hopper
  double rpm = 15.0;
  int pockets_skipped = 1;  ///< pockets closing first (filled at rest) not counted
  int pockets_measured = 8;
};

/// The folder holding repeat `repeat` (1-based) of a discharge run's bed under its `out`, after
/// checking the bed is complete there (bed.json and bed.ckpt); InputError naming `--bed-from`
/// otherwise.
std::filesystem::path require_bed(const std::filesystem::path& run_out, int repeat);

/// The scale's parameters for a rig with its (parsed) settings applied. Throws InputError for a
/// setting the scale cannot honour.
ScaleParams rig_scale(const std::string& rig, const std::map<std::string, std::string>& settings);

struct RigRequest {
  std::string rig;
  ParticleModel model;
  std::map<std::string, std::string> settings;  ///< parsed by parse_settings (scale included)
  int repeats = 1;
  std::uint64_t seed = 1;  ///< repeat k uses seed + k
  /// 1 … repeats: make (or keep from `out`) that repeat alone, as the whole request would make
  /// it; 0 = every repeat. A caller runs the repeats of one request side by side this way, each
  /// into the same `out`, and a last call with 0 then keeps them all (the calibration's cache).
  int only_repeat = 0;
  std::filesystem::path out;          ///< checkpoints, per-repeat results, pictures; empty = none
  bool vtk = false;                   ///< write VTK (.vtp) snapshots for ParaView into `out`
  int threads = 0;                    ///< 0 = all
  long rays = 20000;                  ///< ray sampling of the clumps' mass properties
  double checkpoint_interval = 60.0;  ///< s of wall-clock time between checkpoints
  /// discharge only: an earlier run's `out` folder whose beds (each repeat's hopper, filled and at
  /// rest, saved in repeat_K/bed/) this run turns at its own speed instead of pouring its own:
  /// the paper's procedure, one bed turned at 10, 15 and 30 rpm. The model, scale (but the
  /// wheel's speed and the pockets counted), seed and rays must be the bed's (InputError
  /// otherwise).
  std::filesystem::path bed_from;
  /// discharge only: keep each repeat's bed in `out` (repeat_K/bed/, the size of a checkpoint) for
  /// a later run's bed_from. The calibration's rig runs do not (their cache would double).
  bool keep_bed = true;
  /// "clumpkit" (the bundled runner) or "liggghts": the rig written as a LIGGGHTS 3.8 deck and
  /// run there (every rig; not with bed_from), for runs that outgrow one machine. Each
  /// repeat's deck, meshes and templates stay in `out`/repeat_K/liggghts/.
  std::string engine = "clumpkit";
  int liggghts_ranks = 1;  ///< MPI ranks of a LIGGGHTS run (mpirun -np); 1 = no mpirun
  std::function<void(const std::string&)> progress;  ///< one line per call, may be empty
  /// s of wall-clock time between the progress lines of the long loops (pour, settle, strike-off,
  /// lift, discharge); 0 = one line per check (tests that stop a run at a given check).
  double progress_every = 5.0;
  /// Edits the scale's parameters after the settings are applied (tests and studies that need
  /// a rig smaller than `mini`); recorded in the result like any other parameter.
  std::function<void(ScaleParams&)> adjust;
};

struct RepeatResult {
  std::uint64_t seed = 0;
  std::map<std::string, double> values;  ///< quantity name → value in SI units
  nlohmann::json details;                ///< rig-specific figures (SI), settle info, timings
  double wall_seconds = 0.0;
  bool resumed = false;
};

struct QuantityStats {
  double mean = 0.0, std = 0.0;  ///< SI; std of the repeats (0 for one repeat)
  int n = 0;
};

struct RigResult {
  std::string rig, model, scale;
  std::map<std::string, std::string> settings;
  ScaleParams params;
  std::vector<RepeatResult> repeats;
  std::map<std::string, QuantityStats> stats;  ///< per quantity, SI
  std::string error;  ///< set when a repeat failed (blow-up); finished repeats are kept
  nlohmann::json to_json() const;
};

/// Checks an engine choice before anything runs: InputError for an unknown engine, MPI ranks
/// (`ranks` > 1) for the bundled runner, or a LIGGGHTS (or, for ranks > 1, an mpirun) that is not
/// installed.
void check_engine(const std::string& engine, int ranks);

/// Runs all repeats. A repeat that blows up stops the run: the result then holds the finished
/// repeats and `error`; the caller decides the exit status.
RigResult run_rig(const RigRequest& request);

/// Mean and sample standard deviation of the repeats' values.
std::map<std::string, QuantityStats> repeat_stats(const std::vector<RepeatResult>& repeats);

}  // namespace clumpkit::rigs
