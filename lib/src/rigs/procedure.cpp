#include "procedure.hpp"

#include <fmt/format.h>

#include <cmath>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/rigs/pictures.hpp"
#include "clumpkit/sim/vtk_output.hpp"

namespace clumpkit::rigs::detail {

namespace fs = std::filesystem;
using Eigen::Vector3d;

dem::WorldSettings base_settings(const Ctx& c, const std::vector<std::string>& wall_materials) {
  dem::WorldSettings ws;
  ws.source = c.req.model.path.string();
  ws.materials = c.req.model.materials;
  ws.rolling_model = c.req.model.effects.rolling_model.value_or(dem::RollingModel::kStandard);
  ws.clump_types = c.types;
  ws.pair_contacts = c.req.model.pair_contacts(wall_materials);
  if (c.p.stiffness_scale != 1.0)
    for (const auto& n : ws.materials.names()) {
      Material m = ws.materials.get(n);
      m.youngs_modulus *= c.p.stiffness_scale;
      ws.materials.add(m);
    }
  ws.rayleigh_fraction = c.p.rayleigh_fraction;
  ws.implicit_damping = c.p.implicit_damping ? dem::kImplicitDampingGate : 0.0;
  ws.threads = c.req.threads;
  ws.seed = c.seed;
  ws.max_impact_speed = 2.5;
  // The rigs' moving walls (scraper, wheel) pass fixed edges: a pill caught there is taken
  // out at 25 % overlap instead of stopping the run, and reported (pinch_json).
  ws.pinch_release = 0.25;
  return ws;
}

double mean_union_density(const Ctx& c) {
  double v = 0, m = 0;
  const std::vector<dem::MixtureEntry> mix = c.req.model.mixture();
  for (const auto& t : c.types)
    for (const auto& e : mix)
      if (e.clump_type == t.name) m += e.mass_fraction, v += e.mass_fraction / t.clump.mass.density;
  return m / v;
}

double max_bound_radius(const Ctx& c) {
  double r = 0;
  for (const auto& t : c.types)
    for (const auto& s : t.clump.spheres) r = std::max(r, s.center.norm() + s.radius);
  return r;
}

// A factory pouring `mass` into `region`: all at once when the region can hold it at a loose
// 20 % solid fraction, else at the scale's pour rate or as fast as the region can take pills,
// whichever is slower (the small scale's cup asked more of its pour region per batch than
// random insertion could place, and the factory stopped the run as falling behind).
dem::FactorySettings pour(const Ctx& c, const dem::Region& region, double mass) {
  dem::FactorySettings f;
  f.name = "pour";
  f.region = region;
  f.mixture = c.req.model.mixture();
  f.mass = mass;
  const double capacity = dem::region_volume(region) * 0.2 * mean_union_density(c);
  f.rate = mass <= capacity ? 0.0 : c.p.pour_rate;
  f.fail_if_behind = false;
  f.velocity = Vector3d(0, 0, -0.1);
  return f;
}

// The engine checkpoint and the rig's state (state.json: phase, lift end, pocket fills, ...) are
// one commit: the checkpoint goes to a new file named by phase and step, then state.json names
// it (atomic rename), then older checkpoints are deleted. A kill at any moment leaves a
// state.json and the checkpoint it names, taken at the same step. (Writing both under fixed
// names let a kill between the two writes pair a new checkpoint with an old state: a resume in
// the middle of the angle-of-repose lift then stopped the tube twice, 26.3477° instead of
// 26.3464°.)
void keep_checkpoint(Ctx& c, dem::World& w, int phase, const nlohmann::json& extra, bool now) {
  if (c.dir.empty()) return;
  const double since = std::chrono::duration<double>(Clock::now() - c.last_checkpoint).count();
  if (!now && since < c.req.checkpoint_interval) return;
  const std::string name = fmt::format("phase{}_step{}.ckpt", phase, w.step_count());
  w.save_checkpoint(c.dir / name);
  nlohmann::json st = extra;
  st["phase"] = phase;
  st["checkpoint"] = name;
  write_file_atomic(c.dir / "state.json", st.dump(2));
  for (const auto& e : fs::directory_iterator(c.dir))
    if (e.path().extension() == ".ckpt" && e.path().filename() != name) {
      std::error_code ec;
      fs::remove(e.path(), ec);
    }
  c.last_checkpoint = Clock::now();
}

double rms_speed(const dem::World& w) {
  const double m = w.total_mass();
  return m > 0 ? std::sqrt(2.0 * w.kinetic_energy() / m) : 0.0;
}

// The engine's stage profile and throughput, for the JSON and the progress stream.
nlohmann::json profile_json(const Ctx& c, const dem::World& w, double sphere_steps) {
  const dem::Profile& pr = w.profile();
  c.say("engine profile:\n" + pr.table());
  return {{"steps", pr.steps},
          {"neighbour_rebuilds", pr.neighbour_rebuilds},
          {"neighbour_rebuilds_spared", pr.neighbour_rebuilds_spared},
          {"engine_seconds", pr.total()},
          {"integrate_s", pr.integrate},
          {"walls_s", pr.walls},
          {"insert_s", pr.insert},
          {"neighbours_s", pr.neighbours},
          {"contacts_s", pr.contacts},
          {"forces_s", pr.forces},
          {"checks_s", pr.checks},
          {"sphere_steps_per_s", pr.total() > 0 ? sphere_steps / pr.total() : 0.0},
          {"clump_steps", pr.clump_steps},
          {"implicit_damping_clump_steps", pr.implicit_clump_steps}};
}

// Pills taken out by the pinch release: said once, and listed in the repeat's details.
nlohmann::json pinch_json(const Ctx& c, const dem::World& w) {
  if (w.pinched_count() > 0)
    c.say(
        fmt::format("warning: {} pill(s), {:.4g} kg, pinched by a moving wall and taken out "
                    "of the run (the first: {})",
                    w.pinched_count(), w.pinched_mass(), [&] {
                      for (const auto& m : w.warnings())
                        if (m.rfind("a clump was pinched", 0) == 0) return m;
                      return std::string("see the engine's warnings");
                    }()));
  return {{"pills", w.pinched_count()}, {"kg", w.pinched_mass()}};
}

// Removes the clumps that have left the rig; returns their mass.
double cull(Ctx& c, dem::World& w) {
  c.meter.tick(w);
  if (!c.outside) return 0.0;
  double m = 0.0;
  const auto& x = w.positions();
  w.remove_clumps([&](int i) {
    if (!c.outside(x[i])) return false;
    m += w.clump_mass(i);
    return true;
  });
  c.removed_mass += m;
  return m;
}

// Runs until the factories are done and the RMS clump speed stays below the scale's threshold
// for 3 checks 10 ms apart, or until settle_max of simulated time after the factories finished
// (constant-torque rolling friction can keep a few pills creeping: the bed counts as settled
// then, and the details say so).
SettleInfo settle(Ctx& c, dem::World& w, int phase, const nlohmann::json& extra,
                  const std::string& what, const std::function<bool()>& stop) {
  SettleInfo s;
  double t_begin = w.time();
  double t_factories = w.factories_done() ? w.time() : -1.0;
  int quiet = 0;
  // Resumed from a checkpoint taken inside this settle (same phase, same time): continue its
  // bookkeeping, so that it ends where an uninterrupted run's does.
  if (!c.dir.empty() && path_exists(c.dir / "state.json")) {
    try {
      const auto saved = nlohmann::json::parse(read_file(c.dir / "state.json"));
      if (saved.value("phase", 0) == phase && saved.contains("settle") &&
          saved["settle"].value("t", -1.0) == w.time()) {
        t_begin = saved["settle"].at("t_begin");
        t_factories = saved["settle"].at("t_factories");
        quiet = saved["settle"].at("quiet");
        // The mass culled so far in this phase (the discharger reports what leaked in its fill).
        c.removed_mass = saved["settle"].value("removed_kg", c.removed_mass);
      }
    } catch (const nlohmann::json::exception&) {
    }
  }
  const double check = 0.01;
  while (true) {
    w.run_until(w.time() + check);
    cull(c, w);
    if (t_factories < 0 && w.factories_done()) t_factories = w.time();
    s.rms_speed = rms_speed(w);
    if (t_factories >= 0 && stop && stop()) {
      s.stopped = true;
      break;
    }
    quiet = (t_factories >= 0 && s.rms_speed < c.p.settle_speed) ? quiet + 1 : 0;
    c.progress([&] {
      return fmt::format("{}: t = {:.3f} s, {} clumps, rms speed {:.4f} m/s", what, w.time(),
                         w.clump_count(), s.rms_speed);
    });
    if (quiet >= 3) {
      s.settled = true;
      break;
    }
    if (t_factories >= 0 && w.time() - t_factories > c.p.settle_max) break;
    if (t_factories < 0 && w.time() - t_begin > 60.0 * c.p.settle_max)
      throw NumericalError(what + ": the factory did not finish in " +
                           fmt::format("{:.1f}", w.time() - t_begin) + " s");
    // Checkpoint only when the loop goes on (a resume continues with the next check).
    nlohmann::json st = extra;
    st["settle"] = {{"t", w.time()},
                    {"t_begin", t_begin},
                    {"t_factories", t_factories},
                    {"quiet", quiet},
                    {"removed_kg", c.removed_mass}};
    keep_checkpoint(c, w, phase, st, false);
  }
  s.time = w.time() - t_begin;
  return s;
}

nlohmann::json settle_json(const SettleInfo& s) {
  return {{"settled", s.settled}, {"time_s", s.time}, {"rms_speed_m_s", s.rms_speed}};
}

Spheres world_spheres(const dem::World& w) {
  Spheres s;
  s.reserve(w.sphere_positions().size());
  for (size_t i = 0; i < w.sphere_positions().size(); ++i)
    s.push_back({w.sphere_positions()[i], w.sphere_radii()[i]});
  return s;
}

void snapshot(const Ctx& c, const dem::World& w, const std::string& name) {
  if (!c.req.vtk || c.dir.empty()) return;
  write_file_atomic(c.dir / (name + "_spheres.vtp"), sim::particles_vtp(w));
  for (int k = 0; k < w.wall_count(); ++k)
    write_file_atomic(c.dir / fmt::format("{}_wall_{}.vtp", name, w.wall_settings(k).name),
                      sim::wall_vtp(w, k));
}

dem::VelocityProfile step_velocity(double t_on, double t_off, const Vector3d& v) {
  dem::VelocityProfile p;
  const double ramp = 1e-4;
  p.times = {t_on, t_on + ramp};
  p.velocities = {Vector3d::Zero(), v};
  if (std::isfinite(t_off)) {
    p.times.insert(p.times.end(), {t_off, t_off + ramp});
    p.velocities.insert(p.velocities.end(), {v, Vector3d::Zero()});
  }
  return p;
}

nlohmann::json load_state(const Ctx& c) {
  if (c.dir.empty() || !path_exists(c.dir / "state.json")) return {{"phase", 0}};
  try {
    return nlohmann::json::parse(read_file(c.dir / "state.json"));
  } catch (const nlohmann::json::exception&) {
    return {{"phase", 0}};
  }
}

// The repeat's World: created from `ws` (walls at rest), then restored from the checkpoint of
// the phase the state names, if any (the checkpoint carries the walls' motions).
dem::World open_world(Ctx& c, const dem::WorldSettings& ws, const nlohmann::json& state,
                      const std::string& what) {
  dem::World w = dem::World::create(ws);
  for (const auto& m : w.warnings()) c.say("warning: " + m);
  const int phase = state.value("phase", 0);
  if (!c.dir.empty() && phase >= 1) {
    // Older runs wrote phaseN.ckpt without naming it in the state.
    const fs::path ck =
        c.dir / (state.contains("checkpoint") ? state.at("checkpoint").get<std::string>()
                                              : fmt::format("phase{}.ckpt", phase));
    if (!path_exists(ck))
      throw InputError((c.dir / "state.json").string(), "checkpoint",
                       "names " + ck.filename().string() +
                           ", which is missing: delete the repeat's folder to start it again");
    {
      w.load_checkpoint(ck);
      c.say(fmt::format("resumed {} (phase {}) at t = {:.3f} s", what, phase, w.time()));
    }
  }
  c.say(fmt::format("{}: time step {:.3g} s", what, w.dt()));
  c.meter.last_steps = w.step_count();
  return w;
}

// Phase 1: pour and settle.
SettleInfo pour_and_settle(Ctx& c, dem::World& w, const std::string& what,
                           const nlohmann::json& extra, const std::function<bool()>& stop) {
  SettleInfo info = settle(c, w, 1, extra, what, stop);
  if (info.stopped) {
    c.say(fmt::format("{}: poured by {:.3f} s, {} clumps, rms speed {:.4f} m/s", what, w.time(),
                      w.clump_count(), info.rms_speed));
    return info;
  }
  c.say(fmt::format("{}: {} after {:.3f} s, {} clumps, rms speed {:.4f} m/s", what,
                    info.settled ? "settled" : "settle time cap reached", w.time(), w.clump_count(),
                    info.rms_speed));
  return info;
}

// Phase 2 begins: the action's wall starts moving in the same World (contact histories kept).
void start_action(Ctx& c, dem::World& w, int wall, const dem::WallMotion& m,
                  nlohmann::json& state) {
  w.set_wall_motion(wall, m);
  state["phase"] = 2;
  keep_checkpoint(c, w, 2, state, true);
}

}  // namespace clumpkit::rigs::detail
