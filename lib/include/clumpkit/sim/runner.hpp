#pragma once
/// Runs a scene to its end time with outputs, progress, checkpoints and resume.
///
/// The output folder holds: `run.json` (what is being run, status), `series.csv` (time series:
/// kinetic energy, contacts, clumps, mass in each named region, force and torque on each wall),
/// `vtk/` + `particles.pvd`, `walls.pvd` (ParaView), `checkpoint_<step>.bin` + `state.json`
/// (the latest checkpoint; `state.json` is renamed last, so it always names a complete one), and
/// `profile.txt` (time per stage).
#include <cstdint>
#include <filesystem>

#include "clumpkit/dem/profile.hpp"
#include "clumpkit/sim/scene.hpp"

namespace clumpkit::sim {

struct RunOptions {
  std::filesystem::path out;  ///< output folder (created)
  double until = 0.0;         ///< s; 0 = the scene's
  int threads = 0;            ///< 0 = the scene's (or all cores)
  bool progress = true;       ///< a progress line on stderr every few seconds
};

struct RunSummary {
  double time = 0.0;  ///< simulated time reached, s
  long steps = 0;
  double wall_seconds = 0.0;
  std::uint64_t state_hash = 0;
  bool interrupted = false;  ///< stopped by SIGINT/SIGTERM after writing a checkpoint
  long clumps = 0;
  long spheres = 0;
  dem::Profile profile;
};

/// Starts a fresh run (the folder must not hold another run's state).
RunSummary run_scene(const Scene& scene, const RunOptions& options);

/// Continues the run in `folder` from its last checkpoint; ends in the same state as an
/// uninterrupted run. Throws InputError if the folder holds no resumable run.
RunSummary resume_run(const std::filesystem::path& folder, const std::filesystem::path& data_dir,
                      bool progress = true);

/// Installs SIGINT/SIGTERM handlers that ask the running simulation to checkpoint and stop.
void install_stop_handlers();

}  // namespace clumpkit::sim
