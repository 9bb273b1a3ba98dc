#include "clumpkit/sim/runner.hpp"

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <iostream>
#include <nlohmann/json.hpp>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/dem/factory.hpp"
#include "clumpkit/sim/vtk_output.hpp"

namespace clumpkit::sim {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) {
  g_stop.store(true);
}

std::string duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  const long t = std::lround(s);
  return t >= 3600 ? fmt::format("{}h{:02d}m", t / 3600, (t / 60) % 60)
                   : fmt::format("{}m{:02d}s", t / 60, t % 60);
}

// Runner bookkeeping that must survive a restart, beside the World's own checkpoint.
struct RunState {
  long frame = 0;                 // next output frame index
  std::vector<std::string> rows;  // series.csv rows so far
  std::vector<std::pair<double, std::string>> particle_frames, wall_frames;
  std::string checkpoint;     // file name of the latest complete checkpoint
  double wall_seconds = 0.0;  // accumulated over sessions
};

class Runner {
 public:
  Runner(const Scene& scene, fs::path out, double until, bool progress)
      : scene_(scene), out_(std::move(out)), until_(until), progress_(progress) {}

  RunSummary run(dem::World& world, RunState& st) {
    fs::create_directories(out_ / "vtk");
    const auto start = Clock::now();
    auto last_progress = start, last_checkpoint = start;
    const double t0 = world.time();
    const long s0 = world.step_count();
    const double every = scene_.output.every;
    RunSummary sum;
    if (st.frame == 0) {
      output(world, st);
      checkpoint(world, st, "running");  // a killed run can always be resumed
    }
    while (world.time() < until_ - 1e-15 * until_) {
      world.step();
      if (world.time() >= st.frame * every - 1e-12 * every) output(world, st);
      const auto now = Clock::now();
      if (progress_ && now - last_progress > std::chrono::seconds(2)) {
        last_progress = now;
        const double el = std::chrono::duration<double>(now - start).count();
        const double rate = (world.step_count() - s0) / std::max(el, 1e-9);
        const double eta = (until_ - world.time()) / std::max(world.time() - t0, 1e-300) * el;
        std::cerr << fmt::format(
            "sim: t = {:.4f} / {:.4f} s ({:.1f} %)  {:.3g} steps/s  {:.3g} sphere-steps/s  "
            "ETA {}  {} clumps  KE {:.3g} J\n",
            world.time(), until_, 100.0 * world.time() / until_, rate,
            rate * static_cast<double>(world.sphere_count()), duration(eta), world.clump_count(),
            world.kinetic_energy());
      }
      const bool stop = g_stop.load();
      if (stop || now - last_checkpoint >
                      std::chrono::duration<double>(60.0 * scene_.output.checkpoint_minutes)) {
        last_checkpoint = now;
        st.wall_seconds += std::chrono::duration<double>(now - start).count();
        checkpoint(world, st, "running");
        st.wall_seconds -= std::chrono::duration<double>(now - start).count();
        if (stop) {
          sum.interrupted = true;
          break;
        }
      }
    }
    st.wall_seconds += std::chrono::duration<double>(Clock::now() - start).count();
    if (!sum.interrupted) {
      if (st.particle_frames.empty() || st.particle_frames.back().first < world.time())
        output(world, st);
      checkpoint(world, st, "finished");
      write_file_atomic(out_ / "profile.txt", world.profile().table());
    }
    sum.time = world.time();
    sum.steps = world.step_count();
    sum.wall_seconds = st.wall_seconds;
    sum.state_hash = world.state_hash();
    sum.clumps = world.clump_count();
    sum.spheres = world.sphere_count();
    sum.profile = world.profile();
    return sum;
  }

 private:
  std::string header(const dem::World& w) const {
    std::string h = "time_s,kinetic_energy_J,clumps,contacts";
    for (const auto& r : scene_.regions) h += ",mass_" + r.name + "_kg";
    for (int k = 0; k < w.wall_count(); ++k) {
      const std::string n = w.wall_settings(k).name;
      h += fmt::format(",{0}_Fx_N,{0}_Fy_N,{0}_Fz_N,{0}_Tx_Nm,{0}_Ty_Nm,{0}_Tz_Nm", n);
    }
    return h;
  }

  void output(dem::World& w, RunState& st) {
    const auto t_start = Clock::now();
    std::string row = fmt::format("{:.9g},{:.9g},{},{}", w.time(), w.kinetic_energy(),
                                  w.clump_count(), w.contact_count());
    for (const auto& r : scene_.regions) {
      double m = 0;
      for (int c = 0; c < w.clump_count(); ++c)
        if (dem::region_contains(r.region, w.positions()[c])) m += w.clump_mass(c);
      row += fmt::format(",{:.9g}", m);
    }
    for (int k = 0; k < w.wall_count(); ++k) {
      const auto& ws = w.wall(k);
      row += fmt::format(",{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}", ws.force[0], ws.force[1],
                         ws.force[2], ws.torque[0], ws.torque[1], ws.torque[2]);
    }
    st.rows.push_back(row);
    std::string csv = header(w) + "\n";
    for (const auto& r : st.rows) csv += r + "\n";
    write_file_atomic(out_ / "series.csv", csv);
    if (scene_.output.vtk) {
      const std::string p = fmt::format("vtk/particles_{:05d}.vtp", st.frame);
      const std::string wl = fmt::format("vtk/walls_{:05d}.vtp", st.frame);
      write_file_atomic(out_ / p, particles_vtp(w));
      write_file_atomic(out_ / wl, walls_vtp(w));
      st.particle_frames.emplace_back(w.time(), p);
      st.wall_frames.emplace_back(w.time(), wl);
      write_file_atomic(out_ / "particles.pvd", pvd(st.particle_frames));
      write_file_atomic(out_ / "walls.pvd", pvd(st.wall_frames));
    }
    ++st.frame;
    w.profile().output += std::chrono::duration<double>(Clock::now() - t_start).count();
  }

  void checkpoint(const dem::World& w, RunState& st, const char* status) {
    const std::string name = fmt::format("checkpoint_{:010d}.bin", w.step_count());
    if (name != st.checkpoint) {
      const fs::path tmp = out_ / (name + ".partial");
      w.save_checkpoint(tmp);
      fs::rename(tmp, out_ / name);
    }
    const std::string old = st.checkpoint;
    st.checkpoint = name;
    json j = {{"status", status},
              {"time_s", w.time()},
              {"steps", w.step_count()},
              {"frame", st.frame},
              {"rows", st.rows},
              {"particle_frames", st.particle_frames},
              {"wall_frames", st.wall_frames},
              {"checkpoint", st.checkpoint},
              {"wall_seconds", st.wall_seconds},
              {"state_hash", fmt::format("{:016x}", w.state_hash())}};
    write_file_atomic(out_ / "state.json", j.dump(1) + "\n");  // the commit point
    if (!old.empty() && old != name) {
      std::error_code ec;
      fs::remove(out_ / old, ec);
    }
  }

  const Scene& scene_;
  fs::path out_;
  double until_;
  bool progress_;
};

void write_run_json(const fs::path& out, const Scene& scene, const RunOptions& o, double until,
                    int threads) {
  json j = {{"format", "clumpkit-run/1"},
            {"scene", fs::absolute(scene.path).string()},
            {"until_s", until},
            {"threads", threads}};
  write_file_atomic(out / "run.json", j.dump(2) + "\n");
}

}  // namespace

void install_stop_handlers() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
}

RunSummary run_scene(const Scene& scene, const RunOptions& o) {
  std::error_code ec;
  if (fs::exists(o.out / "state.json", ec))
    throw InputError(o.out.string(), "--out",
                     "already holds a run (state.json): resume it with --resume, or choose another "
                     "folder");
  Scene s = scene;
  if (o.threads > 0) s.world.threads = o.threads;
  const double until = o.until > 0 ? o.until : s.until;
  // The physics is validated before the output folder is created: a refused scene leaves nothing.
  dem::World world = dem::World::create(s.world);
  fs::create_directories(o.out, ec);
  check_writable(o.out / "run.json", "--out");
  for (const auto& w : world.warnings()) std::cerr << "sim: warning: " << w << "\n";
  write_run_json(o.out, s, o, until, s.world.threads);
  RunState st;
  Runner r(s, o.out, until, o.progress);
  return r.run(world, st);
}

RunSummary resume_run(const fs::path& folder, const fs::path& data_dir, bool progress) {
  json run, state;
  try {
    run = json::parse(read_file(folder / "run.json"));
    state = json::parse(read_file(folder / "state.json"));
  } catch (const json::exception& e) {
    throw InputError(folder.string(), "--resume", std::string("no resumable run: ") + e.what());
  }
  Scene s = load_scene(run.at("scene").get<std::string>(), data_dir);
  s.world.threads = run.value("threads", 0);
  const double until = run.at("until_s").get<double>();
  dem::World world = dem::World::create(s.world);
  RunState st;
  st.checkpoint = state.at("checkpoint").get<std::string>();
  world.load_checkpoint(folder / st.checkpoint);
  st.frame = state.at("frame").get<long>();
  st.rows = state.at("rows").get<std::vector<std::string>>();
  st.particle_frames =
      state.at("particle_frames").get<std::vector<std::pair<double, std::string>>>();
  st.wall_frames = state.at("wall_frames").get<std::vector<std::pair<double, std::string>>>();
  st.wall_seconds = state.value("wall_seconds", 0.0);
  if (progress)
    std::cerr << fmt::format("sim: resuming {} at t = {:.6g} s (step {})\n", folder.string(),
                             world.time(), world.step_count());
  Runner r(s, folder, until, progress);
  return r.run(world, st);
}

}  // namespace clumpkit::sim
