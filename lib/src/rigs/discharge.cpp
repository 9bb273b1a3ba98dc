// The pocket-wheel discharger (SPEC §7): a hopper over an 8-pocket wheel turning at a
// given rpm; the mass each pocket carries out and the discharged mass over time.
#include "procedure.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/dem/world.hpp"
#include "clumpkit/rigs/geometry.hpp"
#include "clumpkit/rigs/heap_angle.hpp"
#include "clumpkit/rigs/pictures.hpp"

namespace clumpkit::rigs::detail {

using Eigen::Vector3d;
namespace fs = std::filesystem;

namespace {

// Everything that makes a repeat's bed (the hopper filled and at rest, before the wheel turns):
// the model, the scale's parameters but the wheel's speed and the pockets counted, the seed,
// the rays of the clumps' mass properties and the code's revisions.
std::string bed_fingerprint(const Ctx& c) {
  const ScaleParams& p = c.p;
  return fmt::format(
      "{}|seed {}|rays {}|scale {} stiffness {:.17g} implicit {} rayleigh {:.17g} settle {:.17g} "
      "{:.17g} pour {:.17g} {} wheel {:.17g} slice {:.17g} bed {:.17g}|engine {} rigs {}",
      model_fingerprint(c.req.model), c.seed, c.req.rays, p.name, p.stiffness_scale,
      p.implicit_damping, p.rayleigh_fraction, p.settle_speed, p.settle_max, p.pour_rate,
      p.pour_whole_in_region, p.wheel_scale, p.slice_length, p.bed_mass, dem::kPhysicsRevision,
      kDischargeRevision);
}

// The bed is kept in the repeat's folder, bed/ (apart from the running checkpoints, which are
// pruned): bed.ckpt, then bed.json (its state and fingerprint), which marks it complete.
void save_bed(const Ctx& c, const dem::World& w, const nlohmann::json& state) {
  if (c.dir.empty() || !c.req.keep_bed) return;
  const fs::path d = c.dir / "bed";
  fs::create_directories(d);
  w.save_checkpoint(d / "bed.ckpt");
  write_file_atomic(d / "bed.json",
                    nlohmann::json{{"state", state}, {"fingerprint", bed_fingerprint(c)}}.dump(2));
}

// Loads the bed of this repeat from req.bed_from into `w` and returns its state.
nlohmann::json take_bed(Ctx& c, dem::World& w) {
  const fs::path d = require_bed(c.req.bed_from, c.repeat + 1);
  const fs::path meta = d / "bed.json";
  nlohmann::json state;
  std::string fingerprint;
  try {
    const nlohmann::json saved = nlohmann::json::parse(read_file(meta));
    fingerprint = saved.at("fingerprint").get<std::string>();
    state = saved.at("state");
    (void)state.at("t_action").get<double>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(meta.string(), "", std::string("not a bed record: ") + e.what());
  }
  if (fingerprint != bed_fingerprint(c))
    throw InputError(meta.string(), "fingerprint",
                     fmt::format("the bed was made by another model, scale, seed or version (this "
                                 "repeat: seed {}, scale {}); only the wheel's speed (rpm) and "
                                 "the pockets counted may differ",
                                 c.seed, c.p.name));
  w.load_checkpoint(d / "bed.ckpt");
  c.say(fmt::format("bed taken from {} (t = {:.3f} s, {} clumps)", d.string(), w.time(),
                    w.clump_count()));
  state["bed_from"] = d.string();
  return state;
}

}  // namespace

DischargeScene discharge_scene(const Ctx& c) {
  const ScaleParams& p = c.p;
  DischargeScene d;
  d.c = &c;
  WheelGeometry& g = d.g;
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
  dem::WorldSettings& ws = d.ws;
  ws = base_settings(c, mats);
  ws.source = "discharge rig";
  ws.walls.push_back({"housing", housing_mesh(g), "galvanized_steel", {}, {}});
  ws.walls.push_back({"hopper", hopper_mesh(g), "galvanized_steel", {}, {}});
  ws.walls.push_back({"ends", end_plates_mesh(g), "galvanized_steel", {}, {}});
  d.z_out = g.axis_height - g.outer_radius - g.housing_gap - 0.01;
  ws.walls.push_back({"catch",
                      dem::make_plane(Vector3d(0, 0, d.z_out - 0.06), Vector3d::UnitZ(), 0.6, 0.6),
                      "galvanized_steel",
                      {},
                      {}});
  ws.walls.push_back(d.wheel(1e9));
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
  // The pour region: the box over the hopper from 0.4 of its inclined part's height up, cut by
  // the inclined walls' planes 2 mm inside them. (Until session 41 the box was not cut: its lower
  // corners, ~10 % of it, lay beyond the walls and the pills placed there fell past the hopper.
  // Starting a plain box higher, inside the walls, raised every pill's fall instead, and with
  // softened pills that jammed a discharge: bench/tried/pour_box_inside_hopper.diff.)
  const double cos_a = std::cos(g.hopper_half_angle_deg * std::numbers::pi / 180.0);
  const double sin_a = std::sin(g.hopper_half_angle_deg * std::numbers::pi / 180.0);
  const double w0 = 0.5 * g.hopper_opening, margin = 0.002;
  const Vector3d into_left(cos_a, 0, sin_a), into_right(-cos_a, 0, sin_a);
  const dem::BoxRegion box{
      Vector3d(-0.5 * g.hopper_top_width + margin, -ymax, zt + 0.4 * hc),
      Vector3d(0.5 * g.hopper_top_width - margin, ymax, zt + hc + g.hopper_height),
      {{Vector3d(-w0, 0, zt) + margin * into_left, into_left},
       {Vector3d(w0, 0, zt) + margin * into_right, into_right}}};
  dem::FactorySettings fill = pour(c, box, p.bed_mass);
  // Poured at a rate (paper scale: the bed does not fit the region at once), the hopper fills to
  // its top: the paper's 10 kg per 100 mm nearly fills it, and a slice between end plates packs
  // more loosely. Once the region only trickles (a batch places less than a quarter of its
  // share) the fill ends with the hopper full; the JSON reports the bed's mass.
  if (fill.rate > 0.0) fill.end_below = 0.25;
  ws.factories.push_back(fill);

  d.wheel_wall = int(ws.walls.size()) - 1;
  return d;
}

dem::WallSettings DischargeScene::wheel(double t_on) const {
  dem::WallSettings w{"wheel", wheel_mesh(g), "abs_plastic", {}, {}};
  dem::WallRotation rot;
  rot.axis_point = Vector3d(0, 0, g.axis_height);
  rot.axis = Vector3d::UnitY();
  rot.rpm = c->p.rpm;
  rot.start_time = t_on;
  w.motion.rotation = rot;
  return w;
}

PocketSchedule pocket_schedule(const WheelGeometry& g, const ScaleParams& p, double t0) {
  PocketSchedule ps;
  ps.omega = p.rpm * 2.0 * std::numbers::pi / 60.0;  // rad/s, about +y: angles decrease
  ps.pitch = 2.0 * std::numbers::pi / g.pockets;
  ps.period = ps.pitch / ps.omega;
  const double rh = g.outer_radius + g.housing_gap;
  const double throat = std::acos(0.5 * g.hopper_opening / rh);  // right throat edge angle
  // Pocket k lies between vanes k and k+1: angles [a_k, a_k + pitch], a_k(t) = k·pitch − ω(t−t0).
  // It closes when its upper vane passes below the throat edge.
  for (int k = 0; k < g.pockets; ++k) {
    double upper = (k + 1) * ps.pitch;
    while (upper <= throat) upper += 2.0 * std::numbers::pi;
    while (upper > throat + 2.0 * std::numbers::pi) upper -= 2.0 * std::numbers::pi;
    ps.pockets.push_back({t0 + (upper - throat) / ps.omega, k});
  }
  std::sort(ps.pockets.begin(), ps.pockets.end(),
            [](auto& a, auto& b) { return a.t_close < b.t_close; });
  const int need = p.pockets_skipped + p.pockets_measured;
  while (int(ps.pockets.size()) < need) {
    PocketSchedule::Pocket q = ps.pockets[ps.pockets.size() - g.pockets];
    q.t_close += 2.0 * std::numbers::pi / ps.omega;
    ps.pockets.push_back(q);
  }
  ps.settle_delay = 0.05 * ps.period;
  ps.t_end = ps.pockets[need - 1].t_close + ps.settle_delay;
  return ps;
}

double pocket_mass(const std::vector<Vector3d>& centres, const std::vector<double>& masses,
                   const WheelGeometry& g, double lower) {
  const double rh = g.outer_radius + g.housing_gap;
  const double pitch = 2.0 * std::numbers::pi / g.pockets;
  const double L = g.length;
  double m = 0;
  for (size_t i = 0; i < centres.size(); ++i) {
    const Vector3d& x = centres[i];
    const double r = std::hypot(x.x(), x.z() - g.axis_height);
    if (r < g.hub_radius || r > rh || std::abs(x.y()) > 0.5 * L) continue;
    double a = std::atan2(x.z() - g.axis_height, x.x()) - lower;
    a = std::fmod(a, 2.0 * std::numbers::pi);
    if (a < 0) a += 2.0 * std::numbers::pi;
    if (a < pitch) m += masses[i];
  }
  return m;
}

RepeatResult discharge_result(const ScaleParams& p, const WheelGeometry& g,
                              const std::vector<double>& fills, const std::vector<double>& curve_t,
                              const std::vector<double>& curve_m) {
  const double s = p.wheel_scale, L = g.length;
  const double omega = p.rpm * 2.0 * std::numbers::pi / 60.0;
  const double period = 2.0 * std::numbers::pi / g.pockets / omega;
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
               {"jam", discharge_jam(fills)}};
  return r;
}

// A counted pocket that closed with under a quarter of the fullest one's mass: the flow into the
// wheel stopped or nearly stopped, most likely an arch over the throat (in the 24 mm slice of
// mini and tiny a few pills span it). A lab would clear the rig and run again, and so does
// run_rig (detail::run_attempts); the JSON and the log say which pockets starved.
nlohmann::json discharge_jam(const std::vector<double>& fills) {
  if (fills.empty()) return nullptr;
  const double top = *std::max_element(fills.begin(), fills.end());
  if (top <= 0.0)
    return "no counted pocket received a pill: the flow into the wheel never started, most likely "
           "an arch over the throat; a lab would clear the rig and run again";
  std::vector<int> starved;
  for (size_t k = 0; k < fills.size(); ++k)
    if (fills[k] < 0.25 * top) starved.push_back(static_cast<int>(k) + 1);
  if (starved.empty()) return nullptr;
  return fmt::format(
      "counted pocket{} {} closed with less than a quarter of the fullest one's {:.4g} kg: the "
      "flow into the wheel stopped, most likely an arch over the throat; a lab would clear the "
      "rig and run again",
      starved.size() == 1 ? "" : "s", fmt::join(starved, ", "), top);
}

RepeatResult discharge(Ctx& c) {
  const ScaleParams& p = c.p;
  const DischargeScene scene = discharge_scene(c);
  const WheelGeometry& g = scene.g;
  const dem::WorldSettings& ws = scene.ws;
  auto wheel = [&](double t_on) { return scene.wheel(t_on); };
  const double z_out = scene.z_out;
  const int wheel_wall = scene.wheel_wall;
  c.outside = [z_out](const Vector3d& x) { return x.z() < z_out; };

  nlohmann::json state = load_state(c);
  const int phase = state.value("phase", 0);
  if (phase == 1 && !c.req.bed_from.empty())
    throw InputError("--bed-from", c.req.bed_from.string(),
                     fmt::format("{} holds a fill in progress of its own: resume it without "
                                 "--bed-from, or give another --out",
                                 c.dir.string()));
  dem::World w = open_world(c, ws, state, "fill hopper");
  if (phase < 2) {
    if (!c.req.bed_from.empty()) {
      state = take_bed(c, w);
    } else {
      const SettleInfo s1 = pour_and_settle(c, w, "fill hopper");
      // A bed that lost most of what was poured has nothing to discharge: a strongly cohesive
      // model squeezes its pills into each other until the engine releases them as pinched
      // (cohesion 5e5 J/m^3 at tiny: 50 g poured, none left).
      const double poured = w.factory_status(0).inserted_mass;
      if (w.total_mass() < 0.5 * poured)
        throw NumericalError(fmt::format(
            "fill hopper: the bed holds {:.4g} kg of the {:.4g} kg poured ({:.4g} kg fell "
            "through the outlet, {:.4g} kg was released as pinched): nothing to discharge",
            w.total_mass(), poured, c.removed_mass, w.pinched_mass()));
      snapshot(c, w, "bed");
      // Pills that leaked through the outlet while the wheel stood still are not counted.
      state = {{"t_action", w.time() + 0.01},
               {"fill_time_s", w.time()},
               {"settle_fill", settle_json(s1)},
               {"bed",
                {{"asked_kg", p.bed_mass},
                 {"poured_kg", w.factory_status(0).inserted_mass},
                 {"at_rest_kg", w.total_mass()}}},
               {"leaked_kg", c.removed_mass}};
      save_bed(c, w, state);
    }
    c.removed_mass = 0.0;
    state["removed_kg"] = 0.0;
    start_action(c, w, wheel_wall, wheel(state.at("t_action").get<double>()).motion, state);
  }
  const double t0 = state.at("t_action");
  c.removed_mass = state.value("removed_kg", 0.0);

  const PocketSchedule sched = pocket_schedule(g, p, t0);
  const double omega = sched.omega, pitch = sched.pitch, period = sched.period;
  const auto& pockets = sched.pockets;
  const int need = p.pockets_skipped + p.pockets_measured;
  const double settle_delay = sched.settle_delay;
  const double t_end = sched.t_end;

  std::vector<double> fills = state.value("fills", std::vector<double>{});
  std::vector<double> curve_t = state.value("curve_t", std::vector<double>{});
  std::vector<double> curve_m = state.value("curve_m", std::vector<double>{});
  size_t next = state.value("next_pocket", size_t(0));
  const double sample = period / 10.0;
  double t_next_sample = state.value("t_next_sample", w.time());
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
      std::vector<double> masses;
      for (int i = 0; i < w.clump_count(); ++i) masses.push_back(w.clump_mass(i));
      const double m = pocket_mass(w.positions(), masses, g, lower);
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

  RepeatResult r = discharge_result(p, g, fills, curve_t, curve_m);
  r.details.update(nlohmann::json{{"settle_fill", state["settle_fill"]},
                                  {"bed", state.value("bed", nlohmann::json::object())},
                                  {"bed_from", state.value("bed_from", "")},
                                  {"leaked_before_start_kg", state.value("leaked_kg", 0.0)},
                                  {"pills", w.clump_count()},
                                  {"simulated_time_s", w.time()},
                                  {"time_step_s", w.dt()},
                                  {"pinched", pinch_json(c, w)},
                                  {"profile", profile_json(c, w, c.meter.sphere_steps)}});
  if (!c.dir.empty())
    curve_picture(c.dir / "discharge.png", {{fmt::format("{:g} rpm", p.rpm), curve_t, curve_m}},
                  "t s", "m kg");
  return r;
}

}  // namespace clumpkit::rigs::detail

namespace clumpkit::rigs {

std::filesystem::path require_bed(const std::filesystem::path& run_out, int repeat) {
  const std::filesystem::path d = run_out / fmt::format("repeat_{}", repeat) / "bed";
  for (const char* f : {"bed.json", "bed.ckpt"})
    if (!path_exists(d / f))
      throw InputError("--bed-from", run_out.string(),
                       fmt::format("no bed for repeat {} ({} is missing: the run that made it "
                                   "must have finished its fill, with --out)",
                                   repeat, (d / f).string()));
  return d;
}

}  // namespace clumpkit::rigs
