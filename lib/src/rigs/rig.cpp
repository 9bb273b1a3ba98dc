#include "clumpkit/rigs/rig.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/dem/world.hpp"
#include "clumpkit/rigs/geometry.hpp"
#include "clumpkit/rigs/heap_angle.hpp"
#include "clumpkit/rigs/pictures.hpp"

namespace clumpkit::rigs {

namespace fs = std::filesystem;
using Eigen::Vector3d;
using Clock = std::chrono::steady_clock;

// ---------------------------------------------------------------------------------------------
// Scales.

ScaleParams rig_scale(const std::string& rig, const std::map<std::string, std::string>& settings) {
  find_rig(rig);
  ScaleParams p;
  const auto it = settings.find("scale");
  p.name = it == settings.end() ? "mini" : it->second;
  if (p.name == "mini" || p.name == "tiny") {
    // Quick work: softer pills (a larger time step), a smaller cup, a smaller heap lifted
    // faster, a half-size wheel in a two-pill slice.
    p.stiffness_scale = 0.05;
    p.rayleigh_fraction = 0.3;
    p.settle_speed = 0.01;
    p.settle_max = 1.0;
    p.cup_diameter = 0.040, p.cup_height = 0.0386;
    p.pour_rate = 0.3;
    p.scraper_speed = 0.04;
    p.tube_diameter = 0.050, p.tube_height = 0.150;
    p.plate_side = 0.3;
    p.heap_mass = 0.08;
    p.lift_speed = 0.03;
    p.wheel_scale = 0.5;
    // A four-pill slice: in a two-pill (12 mm) slice the pills arch between the end plates
    // above the throat and the pockets stop filling after the first (measured: 5.2, 0.5, 0 g at
    // 10 rpm); at 24 mm they fill steadily (7.9, 10.8, 9.8, 10.8 g at 15 rpm, docs/rigs.md).
    p.slice_length = 0.024;
    p.bed_mass = 0.08;
    p.pockets_measured = 3;
    if (p.name == "tiny") {
      // Smoke tests and the calibration loop's end-to-end test: mini made smaller still
      // (~100-200 pills per rig). Observables are noisier and further from paper scale.
      p.cup_diameter = 0.030, p.cup_height = 0.029;
      p.heap_mass = 0.03, p.tube_diameter = 0.036, p.tube_height = 0.09, p.lift_speed = 0.05;
      p.settle_max = 0.5;
      p.wheel_scale = 0.4, p.slice_length = 0.012, p.bed_mass = 0.025;
    }
  } else if (p.name == "small") {
    p.stiffness_scale = 0.1;
    p.rayleigh_fraction = 0.25;
    p.settle_speed = 0.005;
    p.settle_max = 1.5;
    p.cup_diameter = 0.055, p.cup_height = 0.0531;
    p.pour_rate = 0.3;
    p.scraper_speed = 0.05;
    p.heap_mass = 0.17;  // ~1000 pills: SPEC §7's robust heap
    p.lift_speed = 0.01;
    p.plate_side = 0.4;
    p.wheel_scale = 1.0;
    p.slice_length = 0.020;
    p.bed_mass = 0.4;
    p.pockets_measured = 4;
  } else {
    p.name = "paper";
    p.pour_rate = 0.04;  // the paper's D 20 mm factory pours slowly
    // Pills wholly inside the paper's D 20 x H 20 mm region: ~6 per batch (their centres in a
    // D 11.4 x H 11.4 mm core), 0.02 kg/s, 9.5 s of a 11.5 s run pouring. By centre (LIGGGHTS'
    // default `all_in no`) the region delivers the 0.04 kg/s asked (docs/rigs.md).
    p.pour_whole_in_region = false;
    p.settle_max = 5.0;
  }
  auto num = [&](const char* k) -> std::optional<double> {
    const auto f = settings.find(k);
    if (f == settings.end()) return std::nullopt;
    return std::stod(f->second);
  };
  if (auto v = num("stiffness")) {
    if (*v > 1.0) throw InputError("--set", "stiffness", "must be <= 1 (1 = Table 1)");
    p.stiffness_scale = *v;
  }
  if (const auto f = settings.find("implicit_damping"); f != settings.end())
    p.implicit_damping = f->second == "on";
  if (const auto f = settings.find("pour_region"); f != settings.end())
    p.pour_whole_in_region = f->second == "whole";
  if (auto v = num("lift_speed")) p.lift_speed = *v / 60000.0;
  if (auto v = num("mass")) p.heap_mass = *v;
  if (auto v = num("rpm")) p.rpm = *v;
  if (auto v = num("slice")) p.slice_length = *v * 1e-3;
  if (auto v = num("pockets")) {
    if (*v != std::floor(*v) || *v < 2 || *v > 100)
      throw InputError("--set", "pockets", "must be a whole number in [2, 100]");
    p.pockets_measured = int(*v);
  }
  return p;
}

std::map<std::string, QuantityStats> repeat_stats(const std::vector<RepeatResult>& repeats) {
  std::map<std::string, std::vector<double>> v;
  for (const auto& r : repeats)
    for (const auto& [k, x] : r.values) v[k].push_back(x);
  std::map<std::string, QuantityStats> out;
  for (const auto& [k, xs] : v) {
    QuantityStats s;
    s.n = int(xs.size());
    for (double x : xs) s.mean += x / s.n;
    double ss = 0;
    for (double x : xs) ss += (x - s.mean) * (x - s.mean);
    s.std = s.n > 1 ? std::sqrt(ss / (s.n - 1)) : 0.0;
    out[k] = s;
  }
  return out;
}

namespace {

nlohmann::json params_json(const ScaleParams& p) {
  return {{"name", p.name},
          {"stiffness_scale", p.stiffness_scale},
          {"rayleigh_fraction", p.rayleigh_fraction},
          {"implicit_damping", p.implicit_damping},
          {"settle_speed_m_s", p.settle_speed},
          {"settle_max_s", p.settle_max},
          {"cup_diameter_m", p.cup_diameter},
          {"cup_height_m", p.cup_height},
          {"pour_rate_kg_s", p.pour_rate},
          {"pour_whole_in_region", p.pour_whole_in_region},
          {"scraper_speed_m_s", p.scraper_speed},
          {"tube_diameter_m", p.tube_diameter},
          {"tube_height_m", p.tube_height},
          {"plate_side_m", p.plate_side},
          {"heap_mass_kg", p.heap_mass},
          {"lift_speed_m_s", p.lift_speed},
          {"wheel_scale", p.wheel_scale},
          {"slice_length_m", p.slice_length},
          {"bed_mass_kg", p.bed_mass},
          {"rpm", p.rpm},
          {"pockets_skipped", p.pockets_skipped},
          {"pockets_measured", p.pockets_measured}};
}

// ---------------------------------------------------------------------------------------------
// Shared machinery: settings, checkpoints, settling, phase hand-over.

// Sphere-steps are counted at every settle/action check (the sphere count changes as pills are
// poured and removed).
struct Meter {
  double sphere_steps = 0.0;
  long last_steps = 0;
  void tick(const dem::World& w) {
    sphere_steps += double(w.step_count() - last_steps) * double(w.sphere_count());
    last_steps = w.step_count();
  }
};

struct Ctx {
  const RigRequest& req;
  ScaleParams p;
  std::vector<dem::ClumpTypeSettings> types;  // filled once per run
  fs::path dir;                               // this repeat's folder, may be empty
  std::uint64_t seed = 1;
  int repeat = 0;
  Clock::time_point last_checkpoint = Clock::now();
  Clock::time_point last_progress = Clock::now();
  // Clumps whose centre satisfies `outside` have left the rig for good (overflow, discharge,
  // fallen off the plate): removed from the World; `removed_mass` totals them (phase 2 only
  // resumes it from the state, see discharge).
  std::function<bool(const Vector3d&)> outside = nullptr;
  double removed_mass = 0.0;
  Meter meter = {};

  void say(const std::string& s) const {
    if (req.progress) req.progress(fmt::format("[{} repeat {}] {}", req.rig, repeat + 1, s));
  }
  // A progress line at most every 5 s of wall time on the long loops (pour, strike-off, lift,
  // discharge); `line` is formatted only when one is due.
  template <class F>
  void progress(F&& line) {
    if (std::chrono::duration<double>(Clock::now() - last_progress).count() <= 5.0) return;
    say(line());
    last_progress = Clock::now();
  }
};

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

struct SettleInfo {
  bool settled = false;
  double time = 0.0;     // s simulated in this settle
  double rms_speed = 0;  // m/s at the end
};

// Runs until the factories are done and the RMS clump speed stays below the scale's threshold
// for 3 checks 10 ms apart, or until settle_max of simulated time after the factories finished
// (constant-torque rolling friction can keep a few pills creeping: the bed counts as settled
// then, and the details say so).
SettleInfo settle(Ctx& c, dem::World& w, int phase, const nlohmann::json& extra,
                  const std::string& what) {
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
    st["settle"] = {
        {"t", w.time()}, {"t_begin", t_begin}, {"t_factories", t_factories}, {"quiet", quiet}};
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
  write_spheres_vtp(c.dir / (name + "_spheres.vtp"), w.sphere_positions(), w.sphere_radii(),
                    w.sphere_clumps());
  for (int k = 0; k < w.wall_count(); ++k) {
    std::vector<std::array<int, 3>> tris = w.wall_settings(k).mesh.triangles;
    write_mesh_vtp(c.dir / fmt::format("{}_wall_{}.vtp", name, w.wall_settings(k).name),
                   w.wall_vertices(k), tris);
  }
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
                           const nlohmann::json& extra = {}) {
  SettleInfo info = settle(c, w, 1, extra, what);
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

// ---------------------------------------------------------------------------------------------
// bulk_density

RepeatResult bulk_density(Ctx& c) {
  const ScaleParams& p = c.p;
  const std::string cup_material =
      c.req.settings.count("wall") ? c.req.settings.at("wall") : "organic_glass";
  CupGeometry cup;
  cup.inner_diameter = p.cup_diameter;
  cup.height = p.cup_height;
  const double R = 0.5 * p.cup_diameter, H = p.cup_height;
  const std::vector<std::string> mats = {cup_material, "galvanized_steel"};

  dem::WorldSettings ws = base_settings(c, mats);
  ws.source = "bulk_density rig";
  ws.walls.push_back({"cup", cup_mesh(cup), cup_material, {}, {}});
  ws.walls.push_back({"catch",
                      dem::make_plane(Vector3d(0, 0, -0.005), Vector3d::UnitZ(), 0.5, 0.5),
                      "galvanized_steel",
                      {},
                      {}});
  // Pour until overflow: 0.66 of the pills' own density fills the cup with margin (no pill
  // packs that densely), from a factory 5 mm above the rim (paper: D 20 mm × H 20 mm).
  const double pour_mass = 0.66 * mean_union_density(c) * cup.volume();
  const double fr = p.name == "paper" ? 0.010 : 0.35 * p.cup_diameter;
  const double fh = p.name == "paper" ? 0.020 : 0.6 * p.cup_height;
  ws.factories.push_back(
      pour(c, dem::CylinderRegion{Vector3d(0, 0, H + 0.005), fr, fh}, pour_mass));
  ws.factories.back().whole_in_region = p.pour_whole_in_region;
  // The scraper waits beside the cup; phase 2 moves it across the rim.
  const double x_start = -(R + 0.012), x_end = R + 0.02;
  // The blade clears the rim by a whole pill (its bounding-sphere diameter): a pill lying across
  // the rim cannot be wedged between blade and rim. Blades one sphere diameter (or less) above
  // the rim wedged such pills and the engine stopped with overlaps of 50-85 % of a radius.
  // Pills are weighed by their centre, so what the blade leaves above the rim is not counted.
  const double clearance = 2.0 * max_bound_radius(c);
  auto scraper = [&](double t_on) {
    dem::WallSettings s{
        "scraper", scraper_mesh(x_start, R + 0.02, H + clearance, 0.06), cup_material, {}, {}};
    // The blade leans back 45° (its face looks forward and up, as a grader's): the pills it meets
    // are lifted over the pile instead of being driven into the bed, where a vertical blade
    // jammed them (the engine stopped with 67-81 % overlaps).
    for (Vector3d& v : s.mesh.vertices) v.x() -= v.z() - (H + clearance);
    s.motion.translation = step_velocity(t_on, t_on + (x_end - x_start) / p.scraper_speed,
                                         Vector3d(p.scraper_speed, 0, 0));
    return s;
  };

  ws.walls.push_back(scraper(1e9));
  const int scraper_wall = int(ws.walls.size()) - 1;
  // Pills that fell past the rim onto the catch plate no longer matter: removed as they land.
  c.outside = [](const Vector3d& x) { return x.z() < 0.0; };

  nlohmann::json state = load_state(c);
  dem::World w = open_world(c, ws, state, "pour");
  if (state.value("phase", 0) < 2) {
    const SettleInfo s1 = pour_and_settle(c, w, "pour");
    double top = 0;
    for (int i = 0; i < w.clump_count(); ++i)
      if (w.positions()[i].head<2>().norm() < R) top = std::max(top, w.positions()[i].z());
    snapshot(c, w, "poured");
    // The scraper starts 10 ms after the bed has settled, in the same World.
    state = {{"t_action", w.time() + 0.01}, {"settle_pour", settle_json(s1)}, {"bed_top_m", top}};
    start_action(c, w, scraper_wall, scraper(double(state["t_action"])).motion, state);
  }
  if (state.value("bed_top_m", 0.0) < H)
    c.say("warning: the pour did not overflow the rim: the bulk density is a lower bound");
  const double t_scrape = double(state.at("t_action")) + (x_end - x_start) / p.scraper_speed;
  while (w.time() < t_scrape) {
    w.run_until(std::min(t_scrape, w.time() + 0.02));
    cull(c, w);
    keep_checkpoint(c, w, 2, state, false);
    c.progress([&] {
      return fmt::format("strike-off: t = {:.3f} of {:.3f} s, {} clumps", w.time(), t_scrape,
                         w.clump_count());
    });
  }
  c.say(fmt::format("scraped at t = {:.3f} s", w.time()));
  const SettleInfo s2 = settle(c, w, 2, state, "after strike-off");
  snapshot(c, w, "scraped");

  double mass = 0;
  long n = 0;
  for (int i = 0; i < w.clump_count(); ++i) {
    const Vector3d& x = w.positions()[i];
    if (x.head<2>().norm() < R && x.z() > 0 && x.z() < H) mass += w.clump_mass(i), ++n;
  }
  RepeatResult r;
  r.values["bulk_density"] = mass / cup.volume();
  r.details = {{"mass_kg", mass},
               {"pills", n},
               {"cup_volume_m3", cup.volume()},
               {"poured_mass_kg", pour_mass},
               {"bed_top_before_strike_off_m", state.value("bed_top_m", 0.0)},
               {"blade_clearance_m", clearance},
               {"overflowed", state.value("bed_top_m", 0.0) >= H},
               {"settle_pour", state["settle_pour"]},
               {"settle_after_strike_off", settle_json(s2)},
               {"simulated_time_s", w.time()},
               {"time_step_s", w.dt()},
               {"pinched", pinch_json(c, w)},
               {"profile", profile_json(c, w, c.meter.sphere_steps)}};
  return r;
}

// ---------------------------------------------------------------------------------------------
// angle_of_repose

// The mean mass of the pills in the World, kg (half of it is the tolerance on a poured mass:
// a factory by mass stops at the pill that comes closest).
double mean_pill_mass(const dem::World& w) {
  return w.total_mass() / std::max(1, w.clump_count());
}

RepeatResult angle_of_repose(Ctx& c) {
  const ScaleParams& p = c.p;
  const std::string plate_material =
      c.req.settings.count("plate") ? c.req.settings.at("plate") : "galvanized_steel";
  LiftingGeometry g;
  g.inner_diameter = p.tube_diameter;
  g.height = p.tube_height;
  g.plate_side = p.plate_side;
  const double R = 0.5 * p.tube_diameter;
  // Can the tube hold the mass? Densest packing of the pills (0.74 of their own density).
  const double capacity = 0.74 * mean_union_density(c) * std::numbers::pi * R * R * g.height;
  if (p.heap_mass > capacity)
    throw InputError(
        "--set", "mass",
        fmt::format("{:.3f} kg does not fit the {} scale's {:.1f} mm × {:.0f} mm "
                    "cylinder (at most {:.3f} kg)",
                    p.heap_mass, p.name, 1e3 * p.tube_diameter, 1e3 * g.height, capacity));
  const std::vector<std::string> mats = {"abs_plastic", plate_material};
  dem::WorldSettings ws = base_settings(c, mats);
  ws.source = "angle_of_repose rig";
  ws.walls.push_back({"plate", plate_mesh(g), plate_material, {}, {}});
  auto tube = [&](double t_on, double t_off) {
    dem::WallSettings s{"tube", lifting_cylinder_mesh(g), "abs_plastic", {}, {}};
    s.motion.translation = step_velocity(t_on, t_off, Vector3d(0, 0, p.lift_speed));
    return s;
  };
  ws.walls.push_back(tube(1e9, 1e9 + 1));
  // The factory: the tube's column, all at once when it holds the mass at a loose 20 % solid
  // fraction, else at a rate (0.3 kg/s: the column empties downwards as it is refilled). The
  // paper's D 60 × H 20 mm region above the top at the paper's slow pour would spend most of the
  // run pouring, and cannot keep up at the faster rates (the factory reported falling behind).
  const double br = max_bound_radius(c);
  const dem::CylinderRegion column{Vector3d(0, 0, 0.002), R - 0.001, g.height - 0.004};
  const dem::Region region = column;
  dem::FactorySettings fill = pour(c, region, p.heap_mass);
  if (fill.rate > 0) fill.rate = std::max(fill.rate, 0.3);
  ws.factories.push_back(fill);

  // When the column holds less than the mass asked (paper scale: 0.5 kg in the 0.51 L tube needs
  // a solid fraction of 0.71 at the pills' density, more than a poured bed reaches), the rest is
  // poured as the paper does, from its D 60 × H 20 mm region 5 mm above the top (scaled with the
  // tube), once the column is full; what does not fit runs over the rim onto the plate. The
  // top-up is a second factory added when the column has settled; the state names it, so a
  // resumed run creates it again.
  auto top_up = [&](double t_start, double mass) {
    const double rt = R * 60.0 / 65.7;
    dem::FactorySettings f =
        pour(c, dem::CylinderRegion{Vector3d(0, 0, g.height + 0.005), rt, 0.020}, mass);
    f.name = "top-up";
    f.rate = std::max(f.rate, 0.3);
    f.start_time = t_start;
    f.whole_in_region = false;  // by centre: the region holds few whole pills
    return f;
  };
  const int tube_wall = int(ws.walls.size()) - 1;
  // Pills that roll off the plate have left the rig.
  c.outside = [](const Vector3d& x) { return x.z() < -0.02; };

  nlohmann::json state = load_state(c);
  if (state.contains("top_up"))
    ws.factories.push_back(top_up(state["top_up"].at("t"), state["top_up"].at("kg")));
  dem::World w = open_world(c, ws, state, "fill");
  if (state.value("phase", 0) < 2) {
    SettleInfo s1;
    if (!state.contains("top_up")) {
      s1 = pour_and_settle(c, w, "fill");
      const double in_tube = w.factory_status(0).inserted_mass;
      if (p.heap_mass - in_tube > 0.5 * mean_pill_mass(w)) {
        state = {{"top_up", {{"t", w.time()}, {"kg", p.heap_mass - in_tube}}}};
        w.add_factory(top_up(w.time(), p.heap_mass - in_tube));
        c.say(
            fmt::format("the tube holds {:.3f} of the {:.3f} kg asked: pouring the rest from above "
                        "its top, the overflow runs onto the plate",
                        in_tube, p.heap_mass));
        keep_checkpoint(c, w, 1, state, true);
      }
    }
    if (state.contains("top_up")) s1 = pour_and_settle(c, w, "top-up", state);
    const nlohmann::json top_up_state = state.value("top_up", nlohmann::json());
    double poured = 0;
    for (int f = 0; f < w.factory_count(); ++f) poured += w.factory_status(f).inserted_mass;
    if (p.heap_mass - poured > 0.5 * mean_pill_mass(w))
      c.say(
          fmt::format("warning: {:.3f} of the {:.3f} kg asked were poured (the heap reached the "
                      "pour region)",
                      poured, p.heap_mass));
    const nlohmann::json fill_info = {
        {"asked_kg", p.heap_mass},
        {"poured_kg", poured},
        {"column_kg", w.factory_status(0).inserted_mass},
        {"top_up_kg", w.factory_count() > 1 ? w.factory_status(1).inserted_mass : 0.0}};
    double top = 0;
    for (int i = 0; i < w.clump_count(); ++i) top = std::max(top, w.positions()[i].z());
    snapshot(c, w, "filled");
    const double t_on = w.time() + 0.01;
    const double lift = p.lift_height > 0 ? p.lift_height : top + br + 0.01;
    state = {
        {"t_action", t_on},        {"t_lift_end", t_on + lift / p.lift_speed}, {"lift_m", lift},
        {"fill_time_s", w.time()}, {"settle_fill", settle_json(s1)},           {"fill", fill_info},
        {"bed_top_m", top + br}};
    // A resumed phase 2 creates the World with the top-up factory again (same fingerprint).
    if (w.factory_count() > 1) state["top_up"] = top_up_state;
    start_action(c, w, tube_wall, tube(t_on, double(state["t_lift_end"])).motion, state);
  }
  double t_lift = state.at("t_lift_end");
  double lift = state.at("lift_m");
  const double t_on = state.at("t_action");
  // The state is the source of the tube's motion (t_action, t_lift_end); a resumed run sets it
  // from there.
  w.set_wall_motion(tube_wall, tube(t_on, t_lift).motion);
  // Consecutive lift checks with the heap at rest (the settle criterion); kept in the state, so
  // a resumed lift stops where an uninterrupted one does.
  int quiet = state.value("lift_quiet", 0);
  while (w.time() < t_lift) {
    w.run_until(std::min(t_lift, w.time() + 0.02));
    cull(c, w);
    // The tube has done its job once its bottom edge is a pill diameter above every pill inside
    // or below its footprint: it stops there instead of rising over the whole initial bed (the
    // bed slumps as the tube rises, so this saves about half of the lift). It has done it too
    // once the heap is at rest (the settle criterion, on two checks 0.02 s apart) with no pill
    // within 1.5 bounding radii of its shell: nothing the tube does from there on moves a pill
    // (paper scale, session 21: a 60.4 mm lift ending at 22.84 s instead of 71.5 mm at 26.18 s).
    if (p.lift_height <= 0 && w.time() < t_lift) {
      const double bottom = p.lift_speed * (w.time() - t_on);
      const TubeClearance tc = tube_clearance(w.positions(), R, br, bottom, g.height);
      quiet = rms_speed(w) < p.settle_speed ? quiet + 1 : 0;
      if (!tc.in_footprint || (quiet >= 2 && !tc.near_shell)) {
        t_lift = w.time();
        lift = bottom;
        w.set_wall_motion(tube_wall, tube(t_on, t_lift).motion);
        state["t_lift_end"] = t_lift, state["lift_m"] = lift;
        state["lift_stop"] =
            tc.in_footprint ? "heap at rest, clear of the shell" : "cleared the heap";
        keep_checkpoint(c, w, 2, state, true);
        c.say(tc.in_footprint
                  ? fmt::format("the heap is at rest and clear of the tube's shell after a "
                                "{:.1f} mm lift: the tube stops there",
                                1e3 * lift)
                  : fmt::format("the tube cleared the heap after a {:.1f} mm lift", 1e3 * lift));
      }
      state["lift_quiet"] = quiet;
    }
    keep_checkpoint(c, w, 2, state, false);
    c.progress([&] {
      return fmt::format("lifting: t = {:.3f} of {:.3f} s, rms speed {:.4f} m/s", w.time(), t_lift,
                         rms_speed(w));
    });
  }
  const SettleInfo s2 = settle(c, w, 2, state, "heap flow");
  snapshot(c, w, "heap");

  const Spheres spheres = world_spheres(w);
  const HeapAngle h = measure_heap_angle(spheres);
  const double deg = 180.0 / std::numbers::pi;
  RepeatResult r;
  r.values["angle"] = h.angle;
  r.values["angle_left"] = h.angle_left;
  r.values["angle_right"] = h.angle_right;
  nlohmann::json views = nlohmann::json::array();
  for (const auto& v : h.views)
    views.push_back({{"azimuth_deg", v.azimuth * deg},
                     {"left_deg", v.left.angle * deg},
                     {"right_deg", v.right.angle * deg},
                     {"left_rms_m", v.left.rms},
                     {"right_rms_m", v.right.rms}});
  r.details = {{"fit_window", {h.window_low, h.window_high}},
               {"angle_deg", h.angle * deg},
               {"angle_std_over_flanks_deg", h.angle_std * deg},
               {"angle_alt_window_deg", h.alt_angle * deg},
               {"alt_window", {0.3, 0.7}},
               {"window_sensitivity_deg", std::abs(h.angle - h.alt_angle) * deg},
               {"height_over_radius_angle_deg", h.height_over_radius_angle * deg},
               {"heap_height_m", h.height},
               {"heap_base_radius_m", h.base_radius},
               {"max_fit_rms_m", h.max_rms},
               {"views", views},
               {"pills", w.clump_count()},
               {"mass_kg", w.total_mass()},
               {"lift_m", lift},
               {"lift_stop", state.value("lift_stop", "full lift")},
               {"settle_fill", state["settle_fill"]},
               {"fill", state.value("fill", nlohmann::json::object())},
               {"settle_heap", settle_json(s2)},
               {"simulated_time_s", w.time()},
               {"time_step_s", w.dt()},
               {"pinched", pinch_json(c, w)},
               {"profile", profile_json(c, w, c.meter.sphere_steps)}};
  if (!c.dir.empty()) heap_picture(c.dir / "heap.png", spheres, h);
  return r;
}

// ---------------------------------------------------------------------------------------------
// discharge

RepeatResult discharge(Ctx& c) {
  const ScaleParams& p = c.p;
  WheelGeometry g;
  const double s = p.wheel_scale;
  g.outer_radius *= s, g.hub_radius *= s, g.hopper_opening *= s, g.hopper_top_width *= s;
  g.hopper_height *= s;
  g.length = p.slice_length;
  const double br = max_bound_radius(c);
  if (g.length < 2.0 * br + 0.001)
    throw InputError(
        "--set", "slice",
        fmt::format("{:.1f} mm is narrower than one pill ({:.1f} mm)", g.length * 1e3, 2e3 * br));
  const std::vector<std::string> mats = {"abs_plastic", "galvanized_steel"};
  dem::WorldSettings ws = base_settings(c, mats);
  ws.source = "discharge rig";
  auto wheel = [&](double t_on) {
    dem::WallSettings w{"wheel", wheel_mesh(g), "abs_plastic", {}, {}};
    dem::WallRotation rot;
    rot.axis_point = Vector3d(0, 0, g.axis_height);
    rot.axis = Vector3d::UnitY();
    rot.rpm = p.rpm;
    rot.start_time = t_on;
    w.motion.rotation = rot;
    return w;
  };
  ws.walls.push_back({"housing", housing_mesh(g), "galvanized_steel", {}, {}});
  ws.walls.push_back({"hopper", hopper_mesh(g), "galvanized_steel", {}, {}});
  ws.walls.push_back({"ends", end_plates_mesh(g), "galvanized_steel", {}, {}});
  const double z_out = g.axis_height - g.outer_radius - g.housing_gap - 0.01;
  ws.walls.push_back({"catch",
                      dem::make_plane(Vector3d(0, 0, z_out - 0.06), Vector3d::UnitZ(), 0.6, 0.6),
                      "galvanized_steel",
                      {},
                      {}});
  ws.walls.push_back(wheel(1e9));
  // Hopper capacity: the cone plus its vertical extension, at the pills' densest packing.
  const double tan_a = std::tan(g.hopper_half_angle_deg * std::numbers::pi / 180.0);
  const double hc = 0.5 * (g.hopper_top_width - g.hopper_opening) / tan_a;
  const double hopper_volume = g.length * (0.5 * (g.hopper_opening + g.hopper_top_width) * hc +
                                           g.hopper_top_width * g.hopper_height);
  const double cap = 0.74 * mean_union_density(c) * hopper_volume;
  if (p.bed_mass > cap)
    throw InputError("--set", "scale",
                     fmt::format("the {} scale's hopper holds at most {:.3f} kg, not {:.3f} kg",
                                 p.name, cap, p.bed_mass));
  const double zt = g.throat_z();
  const double ymax = 0.5 * g.length - 0.0005;
  const dem::BoxRegion box{
      Vector3d(-0.5 * g.hopper_top_width + 0.002, -ymax, zt + 0.4 * hc),
      Vector3d(0.5 * g.hopper_top_width - 0.002, ymax, zt + hc + g.hopper_height)};
  ws.factories.push_back(pour(c, box, p.bed_mass));

  const int wheel_wall = int(ws.walls.size()) - 1;
  // Pills below the outlet have been discharged: removed from the World, their mass counted.
  c.outside = [z_out](const Vector3d& x) { return x.z() < z_out; };

  nlohmann::json state = load_state(c);
  dem::World w = open_world(c, ws, state, "fill hopper");
  if (state.value("phase", 0) < 2) {
    const SettleInfo s1 = pour_and_settle(c, w, "fill hopper");
    snapshot(c, w, "bed");
    const double t_on = w.time() + 0.01;
    // Pills that leaked through the outlet while the wheel stood still are not counted.
    state = {{"t_action", t_on},
             {"fill_time_s", w.time()},
             {"settle_fill", settle_json(s1)},
             {"leaked_kg", c.removed_mass}};
    c.removed_mass = 0.0;
    state["removed_kg"] = 0.0;
    start_action(c, w, wheel_wall, wheel(t_on).motion, state);
  }
  const double t0 = state.at("t_action");
  c.removed_mass = state.value("removed_kg", 0.0);

  const double omega = p.rpm * 2.0 * std::numbers::pi / 60.0;  // rad/s, about +y: angles decrease
  const double pitch = 2.0 * std::numbers::pi / g.pockets;
  const double period = pitch / omega;
  const double rh = g.outer_radius + g.housing_gap;
  const double throat = std::acos(0.5 * g.hopper_opening / rh);  // right throat edge angle
  // Pocket k lies between vanes k and k+1: angles [a_k, a_k + pitch], a_k(t) = k·pitch − ω(t−t0).
  // It closes when its upper vane passes below the throat edge.
  struct Pocket {
    double t_close;
    int k;
  };
  std::vector<Pocket> pockets;
  for (int k = 0; k < g.pockets; ++k) {
    double upper = (k + 1) * pitch;
    while (upper <= throat) upper += 2.0 * std::numbers::pi;
    while (upper > throat + 2.0 * std::numbers::pi) upper -= 2.0 * std::numbers::pi;
    pockets.push_back({t0 + (upper - throat) / omega, k});
  }
  std::sort(pockets.begin(), pockets.end(), [](auto& a, auto& b) { return a.t_close < b.t_close; });
  const int need = p.pockets_skipped + p.pockets_measured;
  while (int(pockets.size()) < need) {
    Pocket q = pockets[pockets.size() - g.pockets];
    q.t_close += 2.0 * std::numbers::pi / omega;
    pockets.push_back(q);
  }
  const double settle_delay = 0.05 * period;
  const double t_end = pockets[need - 1].t_close + settle_delay;

  // Progress of phase 2 lives in the state (saved with every checkpoint), so a resumed run
  // continues the pocket count and the discharge curve.
  std::vector<double> fills = state.value("fills", std::vector<double>{});
  std::vector<double> curve_t = state.value("curve_t", std::vector<double>{});
  std::vector<double> curve_m = state.value("curve_m", std::vector<double>{});
  size_t next = state.value("next_pocket", size_t(0));
  const double sample = period / 10.0;
  double t_next_sample = state.value("t_next_sample", w.time());
  const double L = g.length;
  while (true) {
    const double t_next_pocket = next < size_t(need) ? pockets[next].t_close + settle_delay : 1e300;
    const double target = std::min({t_end, t_next_pocket, t_next_sample});
    if (target > w.time()) w.run_until(target);
    cull(c, w);
    if (w.time() >= t_next_sample - 1e-12) {
      curve_t.push_back(w.time() - t0);
      curve_m.push_back(c.removed_mass);
      t_next_sample += sample;
    }
    if (next < size_t(need) && w.time() >= t_next_pocket - 1e-12) {
      const double lower = pockets[next].k * pitch - omega * (w.time() - t0);
      double m = 0;
      for (int i = 0; i < w.clump_count(); ++i) {
        const Vector3d& x = w.positions()[i];
        const double r = std::hypot(x.x(), x.z() - g.axis_height);
        if (r < g.hub_radius || r > rh || std::abs(x.y()) > 0.5 * L) continue;
        double a = std::atan2(x.z() - g.axis_height, x.x()) - lower;
        a = std::fmod(a, 2.0 * std::numbers::pi);
        if (a < 0) a += 2.0 * std::numbers::pi;
        if (a < pitch) m += w.clump_mass(i);
      }
      if (int(next) >= p.pockets_skipped) fills.push_back(m);
      c.say(fmt::format("pocket {} closed at t = {:.3f} s: {:.4f} kg in the slice", next + 1,
                        w.time(), m));
      ++next;
    }
    state["fills"] = fills, state["curve_t"] = curve_t, state["curve_m"] = curve_m;
    state["next_pocket"] = next, state["t_next_sample"] = t_next_sample;
    state["removed_kg"] = c.removed_mass;
    keep_checkpoint(c, w, 2, state, false);
    if (w.time() >= t_end - 1e-12 && next >= size_t(need)) break;
    c.progress([&] {
      return fmt::format(
          "discharge: t = {:.3f} of {:.3f} s, {} of {} pockets closed, {:.4f} kg out", w.time(),
          t_end, next, need, c.removed_mass);
    });
  }
  snapshot(c, w, "discharged");

  double mean = 0, ss = 0;
  for (double f : fills) mean += f / fills.size();
  for (double f : fills) ss += (f - mean) * (f - mean);
  const double sd = fills.size() > 1 ? std::sqrt(ss / (fills.size() - 1)) : 0.0;
  // Extrapolation from the slice to the paper's full pocket (100 mm long, full-size wheel).
  const double to_paper = 0.100 / L / (s * s);
  RepeatResult r;
  r.values["pocket_mass"] = mean * to_paper;
  r.values["pocket_mass_cv"] = mean > 0 ? sd / mean : 0.0;
  r.values["mass_flow"] = mean * to_paper * g.pockets * p.rpm / 60.0;
  r.details = {{"pocket_mass_slice_kg", mean},
               {"pocket_fills_slice_kg", fills},
               {"slice_to_paper_factor", to_paper},
               {"pocket_period_s", period},
               {"pocket_volume_m3", g.pocket_volume()},
               {"rpm", p.rpm},
               {"discharged_mass_kg", curve_m.empty() ? 0.0 : curve_m.back()},
               {"curve_time_s", curve_t},
               {"curve_mass_kg", curve_m},
               {"settle_fill", state["settle_fill"]},
               {"leaked_before_start_kg", state.value("leaked_kg", 0.0)},
               {"pills", w.clump_count()},
               {"simulated_time_s", w.time()},
               {"time_step_s", w.dt()},
               {"pinched", pinch_json(c, w)},
               {"profile", profile_json(c, w, c.meter.sphere_steps)}};
  if (!c.dir.empty())
    curve_picture(c.dir / "discharge.png", {{fmt::format("{:g} rpm", p.rpm), curve_t, curve_m}},
                  "t s", "m kg");
  return r;
}

}  // namespace

nlohmann::json RigResult::to_json() const {
  nlohmann::json reps = nlohmann::json::array();
  for (const auto& r : repeats)
    reps.push_back({{"seed", r.seed},
                    {"values", r.values},
                    {"details", r.details},
                    {"wall_seconds", r.wall_seconds},
                    {"resumed", r.resumed}});
  nlohmann::json st = nlohmann::json::object();
  const RigInfo& info = find_rig(rig);
  for (const auto& [k, s] : stats) {
    const QuantityInfo* q = info.quantity(k);
    const double f = q ? q->to_si : 1.0;
    st[k] = {{"mean", s.mean / f}, {"std", s.std / f}, {"n", s.n}, {"unit", q ? q->unit : ""}};
  }
  nlohmann::json j = {{"rig", rig},
                      {"model", model},
                      {"scale", scale},
                      {"settings", format_settings(settings)},
                      {"scale_parameters", params_json(params)},
                      {"quantities", st},
                      {"repeats", reps}};
  if (!error.empty()) j["error"] = error;
  return j;
}

RigResult run_rig(const RigRequest& req) {
  const RigInfo& info = find_rig(req.rig, "", "rig");
  RigResult res;
  res.rig = info.name;
  res.model = req.model.name;
  res.settings = req.settings;
  res.params = rig_scale(req.rig, req.settings);
  if (req.adjust) req.adjust(res.params);
  res.scale = res.params.name;
  Ctx proto{req, res.params, {}, {}, 1, 0};
  if (req.progress) req.progress("building clump templates: " + req.model.summary());
  proto.types = req.model.clump_types(req.rays);
  if (!req.out.empty()) fs::create_directories(req.out);
  for (int k = 0; k < req.repeats; ++k) {
    Ctx c{req, res.params, proto.types, {}, req.seed + std::uint64_t(k), k};
    if (!req.out.empty()) {
      c.dir = req.out / fmt::format("repeat_{}", k + 1);
      fs::create_directories(c.dir);
      const fs::path done = c.dir / "result.json";
      if (path_exists(done)) {
        const auto j = nlohmann::json::parse(read_file(done));
        RepeatResult r;
        r.seed = j.at("seed");
        r.values = j.at("values").get<std::map<std::string, double>>();
        r.details = j.at("details");
        r.wall_seconds = j.at("wall_seconds");
        r.resumed = true;
        if (r.seed == c.seed) {
          if (req.progress)
            req.progress(fmt::format("repeat {}: kept from {}", k + 1, done.string()));
          res.repeats.push_back(r);
          continue;
        }
      }
    }
    const auto t_start = Clock::now();
    RepeatResult r;
    try {
      if (info.name == "bulk_density")
        r = bulk_density(c);
      else if (info.name == "angle_of_repose")
        r = angle_of_repose(c);
      else
        r = discharge(c);
    } catch (const NumericalError& e) {
      res.error = fmt::format("repeat {} (seed {}): {}", k + 1, c.seed, e.what());
      break;
    }
    r.seed = c.seed;
    r.wall_seconds = std::chrono::duration<double>(Clock::now() - t_start).count();
    r.details["wall_seconds"] = r.wall_seconds;
    if (!c.dir.empty())
      write_file_atomic(c.dir / "result.json", nlohmann::json({{"seed", r.seed},
                                                               {"values", r.values},
                                                               {"details", r.details},
                                                               {"wall_seconds", r.wall_seconds}})
                                                   .dump(2));
    res.repeats.push_back(std::move(r));
  }
  res.stats = repeat_stats(res.repeats);
  return res;
}

}  // namespace clumpkit::rigs
