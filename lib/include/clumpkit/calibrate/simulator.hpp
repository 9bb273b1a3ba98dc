#pragma once
/// Where simulated observables come from. The calibration loop asks a Simulator for the
/// observables of one (model, rig, sample, setting) at a number of repeats; RigSimulator runs
/// the real rigs and caches every result on disk, keyed by the model's content, rig, sample,
/// setting, scale, seed and repeats, so nothing is simulated twice.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "clumpkit/calibrate/comparison.hpp"
#include "clumpkit/calibrate/measurements.hpp"
#include "clumpkit/rigs/model.hpp"
#include "clumpkit/rigs/rig.hpp"

namespace clumpkit::calibrate {

/// One rig run to make: rig, sample (pill type name or "mix") and normalised settings
/// (including `scale`).
struct SimRequest {
  std::string rig;
  std::string sample;
  std::map<std::string, std::string> settings;
  std::string key() const;  ///< rig|sample|settings
};

/// Quantity name -> simulated value in the quantity's canonical unit (deg, kg/m^3, kg, 1, kg/s).
using SimValues = std::map<std::string, SimulatedValue>;

/// One rig run the calibration loop will ask for: a model (whole, as given to simulate()) and
/// a request.
struct SimJob {
  ParticleModel model;
  SimRequest request;
  int repeats = 0;  ///< this job's repeats; 0 = those the prefetch() call gives
};

class Simulator {
 public:
  virtual ~Simulator() = default;
  virtual SimValues simulate(const ParticleModel& model, const SimRequest& request, int repeats,
                             std::uint64_t seed) = 0;
  /// Announces runs that will be asked for next, so that a simulator may run them concurrently
  /// and serve the later simulate() calls from its cache. Results never depend on it.
  virtual void prefetch(const std::vector<SimJob>& jobs, int repeats, std::uint64_t seed) {
    (void)jobs, (void)repeats, (void)seed;
  }
  /// Number of simulate() calls that really ran (not served from a cache).
  long runs() const { return runs_; }

 protected:
  long runs_ = 0;
};

/// The model restricted to one sample: a pill type ("A") alone, or the whole mixture ("mix").
/// Throws InputError naming `where` when the model has no such type.
ParticleModel model_for_sample(const ParticleModel& model, const std::string& sample,
                               const std::string& where);

/// The distinct rig runs a set of measurements needs. `scale` is added to each setting that does
/// not give one.
std::vector<SimRequest> requests_for(const std::vector<Measurement>& measurements,
                                     const std::string& scale);

/// Simulates what the measurements need and returns values keyed by Measurement::key().
std::map<std::string, SimulatedValue> simulate_measurements(
    Simulator& sim, const ParticleModel& model, const std::vector<Measurement>& measurements,
    const std::string& scale, int repeats, std::uint64_t seed);

/// The real rigs, with an on-disk cache (one JSON per run, written atomically). A run that fails
/// (NumericalError: a blow-up, a heap too flat to measure) is cached as a failure and thrown
/// again, so a second diagnosis of the same data simulates nothing either.
class RigSimulator final : public Simulator {
 public:
  struct Options {
    std::filesystem::path cache_dir = "clumpkit_cache";
    int threads = 0;  ///< engine threads per rig run (0 = the engine's choice)
    /// Rig runs made at the same time by prefetch() (each with one engine thread): small rigs
    /// gain more from running side by side than from threads inside one run.
    int jobs = 1;
    long rays = 20000;
    /// "clumpkit" (the bundled runner) or "liggghts" (each run a LIGGGHTS deck, rigs::RigRequest
    /// ::engine, on `liggghts_ranks` MPI ranks). LIGGGHTS results are cached under their own keys
    /// (engine and ranks: another decomposition is another trajectory).
    std::string engine = "clumpkit";
    int liggghts_ranks = 1;
    std::function<void(const std::string&)> progress;
  };
  explicit RigSimulator(Options options);
  SimValues simulate(const ParticleModel& model, const SimRequest& request, int repeats,
                     std::uint64_t seed) override;
  /// Runs the jobs not yet in the cache, `Options::jobs` repeats at a time: each repeat of each
  /// job is a task of its own (one engine thread), so the cores stay busy to the end of the
  /// batch. Results are those of the jobs run one by one. The first failure is rethrown once
  /// every task has finished.
  void prefetch(const std::vector<SimJob>& jobs, int repeats, std::uint64_t seed) override;
  /// Requests served from results this simulator did not make itself (an earlier process's;
  /// not what its own prefetch() ran a moment before).
  long cache_hits() const { return hits_; }
  /// PNG pictures (heap silhouettes, discharge curves) of the runs served so far.
  std::vector<std::filesystem::path> pictures() const;

 private:
  struct Entry {
    ParticleModel model;  ///< restricted to the request's sample
    std::string key;
    std::filesystem::path file, run_dir;
  };
  Entry entry(const ParticleModel& model, const SimRequest& request, int repeats,
              std::uint64_t seed) const;
  SimValues run(const Entry& e, const SimRequest& request, int repeats, std::uint64_t seed,
                int threads);
  /// The rig run of an entry: every repeat (only_repeat 0), or that one alone; `quiet`: no
  /// progress lines (a run whose repeats are all kept from their folders).
  rigs::RigResult launch(const Entry& e, const SimRequest& request, int repeats, std::uint64_t seed,
                         int threads, int only_repeat, bool quiet = false);
  /// Keeps a finished run as the entry's cache file; throws NumericalError if it failed.
  SimValues keep(const Entry& e, const SimRequest& request, const rigs::RigResult& r);
  void announce(const Entry& e, const SimRequest& request, int repeats);

  Options opt_;
  long hits_ = 0;
  std::vector<std::filesystem::path> folders_;
  std::set<std::filesystem::path> made_;  ///< cache files this simulator wrote
  long started_ = 0;                      ///< rig runs begun, for the progress lines
  std::chrono::steady_clock::time_point created_ = std::chrono::steady_clock::now();
  std::mutex mutex_;  ///< guards runs_, made_, started_, folders_ and progress output
};

/// Converts a rig result's SI statistics to canonical-unit simulated values per quantity.
SimValues to_canonical(const std::string& rig, const std::map<std::string, double>& mean_si,
                       const std::map<std::string, double>& std_si, int n);

}  // namespace clumpkit::calibrate
