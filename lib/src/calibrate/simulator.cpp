#include "clumpkit/calibrate/simulator.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/rigs/catalogue.hpp"
#include "clumpkit/rigs/rig.hpp"

namespace clumpkit::calibrate {

namespace fs = std::filesystem;
using nlohmann::json;

std::string SimRequest::key() const {
  return rig + "|" + sample + "|" + format_settings(settings);
}

ParticleModel model_for_sample(const ParticleModel& model, const std::string& sample,
                               const std::string& where) {
  if (sample == "mix") return model;
  ParticleModel m = model;
  m.types.clear();
  std::string known;
  for (const auto& t : model.types) {
    known += (known.empty() ? "" : ", ") + t.name;
    if (t.name == sample) {
      m.types.push_back(t);
      m.types.back().mass_fraction = 1.0;
    }
  }
  if (m.types.empty())
    throw InputError(where, "sample",
                     "model '" + model.name + "' has no pill type '" + sample +
                         "' (types: " + known + "; use sample 'mix' for the whole population)");
  // One type of several: its fractions go, its height spread (if any) stays.
  if (m.types.size() < model.types.size() && m.effects.height_spread <= 0)
    m.effects.size_distribution = false;
  return m;
}

std::vector<SimRequest> requests_for(const std::vector<Measurement>& ms, const std::string& scale) {
  std::vector<SimRequest> out;
  std::set<std::string> seen;
  for (const auto& m : ms) {
    SimRequest r{m.rig, m.sample, m.setting};
    if (!r.settings.count("scale")) r.settings["scale"] = scale;
    if (seen.insert(r.key()).second) out.push_back(r);
  }
  return out;
}

SimValues to_canonical(const std::string& rig, const std::map<std::string, double>& mean_si,
                       const std::map<std::string, double>& std_si, int n) {
  const RigInfo& info = find_rig(rig);
  SimValues v;
  for (const auto& q : info.quantities) {
    auto it = mean_si.find(q.name);
    if (it == mean_si.end()) continue;
    SimulatedValue s;
    s.mean = it->second / q.to_si;
    auto sd = std_si.find(q.name);
    s.std = sd == std_si.end() ? 0.0 : sd->second / q.to_si;
    s.n = n;
    v[q.name] = s;
  }
  return v;
}

std::map<std::string, SimulatedValue> simulate_measurements(Simulator& sim,
                                                            const ParticleModel& model,
                                                            const std::vector<Measurement>& ms,
                                                            const std::string& scale, int repeats,
                                                            std::uint64_t seed) {
  std::map<std::string, SimValues> by_request;
  const std::vector<SimRequest> requests = requests_for(ms, scale);
  std::vector<SimJob> jobs;
  for (const SimRequest& r : requests) jobs.push_back({model, r});
  sim.prefetch(jobs, repeats, seed);
  for (const SimRequest& r : requests) by_request[r.key()] = sim.simulate(model, r, repeats, seed);
  std::map<std::string, SimulatedValue> out;
  for (const auto& m : ms) {
    SimRequest r{m.rig, m.sample, m.setting};
    if (!r.settings.count("scale")) r.settings["scale"] = scale;
    const SimValues& v = by_request.at(r.key());
    auto it = v.find(m.quantity);
    if (it == v.end()) throw NumericalError("rig " + m.rig + " produced no value of " + m.quantity);
    out[m.key()] = it->second;
  }
  return out;
}

RigSimulator::RigSimulator(Options options) : opt_(std::move(options)) {}

RigSimulator::Entry RigSimulator::entry(const ParticleModel& model, const SimRequest& req,
                                        int repeats, std::uint64_t seed) const {
  Entry e;
  e.model = model_for_sample(model, req.sample, model.path.string());
  e.key =
      fmt::format("{}|{}|{}|{}|engine {} rigs {}", req.key(), seed, repeats,
                  model_fingerprint(e.model), dem::kPhysicsRevision, rigs::rig_revision(req.rig));
  // The bundled runner's keys are as they always were (caches stay valid); LIGGGHTS's name it.
  if (opt_.engine != "clumpkit")
    e.key += fmt::format("|{} np {}", opt_.engine, std::max(1, opt_.liggghts_ranks));
  const std::string id = fmt::format("{:016x}", std::hash<std::string>{}(e.key));
  e.file = opt_.cache_dir / (req.rig + "_" + id + ".json");
  e.run_dir = opt_.cache_dir / ("run_" + req.rig + "_" + id);
  return e;
}

namespace {
// A cached run: its values, or why the rigs could not measure (a blow-up, a heap too flat for a
// cone: the same model, request and seeds fail the same way again, so a failure is kept too).
struct Cached {
  SimValues values;
  std::string error;
};

// The cached run of an entry, if its file exists, is readable and holds this very key.
std::optional<Cached> read_cached(const fs::path& file, const std::string& key) {
  std::error_code ec;
  if (!fs::exists(file, ec)) return std::nullopt;
  try {
    const json j = json::parse(read_file(file));
    if (j.value("key", "") != key) return std::nullopt;
    Cached c;
    c.error = j.value("error", "");
    if (!c.error.empty()) return c;
    for (const auto& [q, x] : j.at("values").items())
      c.values[q] = {x.at("mean").get<double>(), x.at("std").get<double>(), x.at("n").get<int>()};
    return c;
  } catch (const std::exception&) {
    return std::nullopt;  // a damaged cache entry is recomputed
  }
}
}  // namespace

void RigSimulator::announce(const Entry& e, const SimRequest& req, int repeats) {
  if (!opt_.progress) return;
  std::lock_guard<std::mutex> lock(mutex_);
  // The run's number and the time since this simulator began: a diagnosis's only clock.
  const double minutes =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - created_).count() / 60.0;
  opt_.progress(fmt::format(
      "[rig run {}, {:.1f} min] simulating {} sample {} [{}] model {} x{}{}", ++started_, minutes,
      req.rig, req.sample, format_settings(req.settings), e.model.name, repeats,
      opt_.engine == "clumpkit"
          ? ""
          : fmt::format(" on {} ({} MPI rank(s))", opt_.engine, std::max(1, opt_.liggghts_ranks))));
}

rigs::RigResult RigSimulator::launch(const Entry& e, const SimRequest& req, int repeats,
                                     std::uint64_t seed, int threads, int only_repeat, bool quiet) {
  std::error_code ec;
  fs::create_directories(opt_.cache_dir, ec);
  rigs::RigRequest rr;
  rr.rig = req.rig;
  rr.model = e.model;
  rr.settings = req.settings;
  rr.repeats = repeats;
  rr.only_repeat = only_repeat;
  rr.seed = seed;
  rr.threads = threads;
  rr.rays = opt_.rays;
  rr.out = e.run_dir;
  rr.keep_bed = false;  // nothing turns a cached run's discharger bed again
  rr.engine = opt_.engine;
  rr.liggghts_ranks = opt_.liggghts_ranks;
  if (opt_.progress && !quiet)
    rr.progress = [this](const std::string& s) {
      std::lock_guard<std::mutex> lock(mutex_);
      opt_.progress(s);
    };
  return rigs::run_rig(rr);
}

SimValues RigSimulator::keep(const Entry& e, const SimRequest& req, const rigs::RigResult& r) {
  // The entry keeps the run's values, or why the rigs could not measure (thrown again when asked).
  json entry = {{"key", e.key}, {"result", r.to_json()}};
  SimValues v;
  const std::string why = r.error.empty() ? ""
                                          : fmt::format("rig {} for model {} failed: {}", req.rig,
                                                        e.model.name, r.error);
  if (why.empty()) {
    std::map<std::string, double> mean, sd;
    int n = 0;
    for (const auto& [q, st] : r.stats) {
      mean[q] = st.mean;
      sd[q] = st.std;
      n = st.n;
    }
    v = to_canonical(req.rig, mean, sd, n);
    json values = json::object();
    for (const auto& [q, x] : v) values[q] = {{"mean", x.mean}, {"std", x.std}, {"n", x.n}};
    entry["values"] = values;
  } else {
    entry["error"] = why;
  }
  write_file_atomic(e.file, entry.dump(1));
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++runs_;
    made_.insert(e.file);
  }
  if (!why.empty()) throw NumericalError(why);
  return v;
}

SimValues RigSimulator::run(const Entry& e, const SimRequest& req, int repeats, std::uint64_t seed,
                            int threads) {
  announce(e, req, repeats);
  return keep(e, req, launch(e, req, repeats, seed, threads, 0));
}

SimValues RigSimulator::simulate(const ParticleModel& model, const SimRequest& req, int repeats,
                                 std::uint64_t seed) {
  const Entry e = entry(model, req, repeats, seed);
  folders_.push_back(e.run_dir);
  if (auto c = read_cached(e.file, e.key)) {
    const bool earlier = !made_.count(e.file);  // an earlier process's result, not our prefetch's
    if (earlier) ++hits_;
    if (!c->error.empty())
      throw NumericalError(earlier ? c->error + " (a cached failure)" : c->error);
    return c->values;
  }
  return run(e, req, repeats, seed, opt_.threads);
}

void RigSimulator::prefetch(const std::vector<SimJob>& jobs, int repeats, std::uint64_t seed) {
  if (opt_.jobs <= 1) return;  // simulate() runs them one by one, with opt_.threads each
  struct Pending {
    Entry e;
    SimRequest req;
    int repeats;
    // The run of the lowest repeat that failed, if one did: a job run whole stops there.
    int failed_repeat = 0;
    rigs::RigResult failed;
  };
  std::vector<Pending> todo;
  std::set<fs::path> seen;
  for (const SimJob& j : jobs) {
    const int n = j.repeats > 0 ? j.repeats : repeats;
    Entry e = entry(j.model, j.request, n, seed);
    if (!seen.insert(e.file).second || read_cached(e.file, e.key)) continue;
    todo.push_back({std::move(e), j.request, n, 0, {}});
  }
  // Each repeat of each job is a task (job, repeat): a batch of three jobs of two repeats on two
  // cores no longer ends with one job's two repeats run one after the other on one core while
  // the other waits. A repeat's result depends on its seed only (the same bits on any thread
  // count), and each writes its own repeat_K/ of the job's folder, where the job, run whole
  // below, keeps it.
  std::vector<std::pair<size_t, int>> tasks;
  for (size_t i = 0; i < todo.size(); ++i)
    for (int k = 1; k <= todo[i].repeats; ++k) tasks.emplace_back(i, k);
  if (tasks.size() < 2) return;
  // A task that fails does not stop the others. A repeat the rigs cannot measure is kept as its
  // job's failure (below); any other error is rethrown once every task has finished.
  std::atomic<size_t> next{0};
  std::exception_ptr first_error;
  auto worker = [&] {
    for (size_t t; (t = next++) < tasks.size();) {
      Pending& p = todo[tasks[t].first];
      const int k = tasks[t].second;
      try {
        if (k == 1) announce(p.e, p.req, p.repeats);
        rigs::RigResult r = launch(p.e, p.req, p.repeats, seed, 1, k);
        if (!r.error.empty()) {
          std::lock_guard<std::mutex> lock(mutex_);
          if (p.failed_repeat == 0 || k < p.failed_repeat) {
            p.failed_repeat = k;
            p.failed = std::move(r);
          }
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!first_error) first_error = std::current_exception();
      }
    }
  };
  const size_t workers = std::min<size_t>(static_cast<size_t>(opt_.jobs), tasks.size());
  std::vector<std::thread> pool;
  for (size_t w = 1; w < workers; ++w) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (first_error) std::rethrow_exception(first_error);
  // Each job whole: its repeats are kept from their folders (nothing is simulated again), or
  // its lowest failed repeat is its failure, as when the job runs its repeats in order (the
  // first such failure is rethrown once every job's entry is written).
  for (Pending& p : todo) {
    try {
      keep(p.e, p.req,
           p.failed_repeat > 0 ? p.failed : launch(p.e, p.req, p.repeats, seed, 1, 0, true));
    } catch (const NumericalError&) {
      if (!first_error) first_error = std::current_exception();
    }
  }
  if (first_error) std::rethrow_exception(first_error);
}

std::vector<fs::path> RigSimulator::pictures() const {
  std::vector<fs::path> out;
  std::set<fs::path> seen;
  for (const auto& d : folders_) {
    std::error_code ec;
    if (!seen.insert(d).second || !fs::is_directory(d, ec)) continue;
    for (const auto& e : fs::recursive_directory_iterator(d, ec))
      if (e.path().extension() == ".png") out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace clumpkit::calibrate
