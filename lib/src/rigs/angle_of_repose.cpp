// The angle-of-repose rig (SPEC §7): a tube on a plate filled, lifted at the paper's
// speed, the heap's flanks fitted in side-view silhouettes.
#include "procedure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "clumpkit/core/error.hpp"
#include "clumpkit/dem/world.hpp"
#include "clumpkit/rigs/geometry.hpp"
#include "clumpkit/rigs/heap_angle.hpp"
#include "clumpkit/rigs/pictures.hpp"

namespace clumpkit::rigs::detail {

using Eigen::Vector3d;

namespace {

// The mean mass of the pills in the World, kg (half of it is the tolerance on a poured mass:
// a factory by mass stops at the pill that comes closest).
double mean_pill_mass(const dem::World& w) {
  return w.total_mass() / std::max(1, w.clump_count());
}

}  // namespace

RepeatResult heap_result(const HeapAngle& h) {
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
               {"views", views}};
  return r;
}

AngleOfReposeScene angle_of_repose_scene(const Ctx& c) {
  const ScaleParams& p = c.p;
  AngleOfReposeScene a;
  a.c = &c;
  const std::string plate_material =
      c.req.settings.count("plate") ? c.req.settings.at("plate") : "galvanized_steel";
  LiftingGeometry& g = a.g;
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
  dem::WorldSettings& ws = a.ws;
  ws = base_settings(c, mats);
  ws.source = "angle_of_repose rig";
  ws.walls.push_back({"plate", plate_mesh(g), plate_material, {}, {}});
  ws.walls.push_back(a.tube(1e9, 1e9 + 1));
  // The factory: the tube's column, all at once when it holds the mass at a loose 20 % solid
  // fraction, else at a rate (0.3 kg/s: the column empties downwards as it is refilled). The
  // paper's D 60 × H 20 mm region above the top at the paper's slow pour would spend most of the
  // run pouring, and cannot keep up at the faster rates (the factory reported falling behind).
  a.br = max_bound_radius(c);
  const dem::CylinderRegion column{Vector3d(0, 0, 0.002), R - 0.001, g.height - 0.004};
  const dem::Region region = column;
  dem::FactorySettings fill = pour(c, region, p.heap_mass);
  if (fill.rate > 0) fill.rate = std::max(fill.rate, 0.3);
  // A nearly full column only trickles: at paper scale its last ten batches (of ~300 pills due)
  // placed 5-66 pills each, 8 % of the column in 4.4 of 78 min (session 25). A batch placing
  // less than a quarter of its share ends the column fill; the top-up pours the rest from above.
  fill.end_below = 0.25;
  ws.factories.push_back(fill);
  a.tube_wall = int(ws.walls.size()) - 1;
  return a;
}

dem::WallSettings AngleOfReposeScene::tube(double t_on, double t_off) const {
  dem::WallSettings s{"tube", lifting_cylinder_mesh(g), "abs_plastic", {}, {}};
  s.motion.translation = step_velocity(t_on, t_off, Vector3d(0, 0, c->p.lift_speed));
  return s;
}

// When the column holds less than the mass asked (paper scale: 0.5 kg in the 0.51 L tube needs
// a solid fraction of 0.71 at the pills' density, more than a poured bed reaches), the rest is
// poured as the paper does, from its D 60 × H 20 mm region 5 mm above the top (scaled with the
// tube), once the column is full; what does not fit runs over the rim onto the plate.
dem::FactorySettings AngleOfReposeScene::top_up(double t_start, double mass) const {
  const double R = 0.5 * g.inner_diameter;
  const double rt = R * 60.0 / 65.7;
  dem::FactorySettings f =
      pour(*c, dem::CylinderRegion{Vector3d(0, 0, g.height + 0.005), rt, 0.020}, mass);
  f.name = "top-up";
  f.rate = std::max(f.rate, 0.3);
  f.start_time = t_start;
  f.whole_in_region = false;  // by centre: the region holds few whole pills
  return f;
}

RepeatResult angle_of_repose(Ctx& c) {
  const ScaleParams& p = c.p;
  AngleOfReposeScene a = angle_of_repose_scene(c);
  dem::WorldSettings& ws = a.ws;
  const LiftingGeometry& g = a.g;
  const double R = 0.5 * p.tube_diameter;
  const double br = a.br;
  auto tube = [&](double t_on, double t_off) { return a.tube(t_on, t_off); };
  // The top-up is a second factory added when the column has settled; the state names it, so a
  // resumed run creates it again.
  auto top_up = [&](double t_start, double mass) { return a.top_up(t_start, mass); };
  const int tube_wall = a.tube_wall;
  // Pills that roll off the plate have left the rig.
  c.outside = [](const Vector3d& x) { return x.z() < -0.02; };

  nlohmann::json state = load_state(c);
  if (state.contains("top_up"))
    ws.factories.push_back(top_up(state["top_up"].at("t"), state["top_up"].at("kg")));
  dem::World w = open_world(c, ws, state, "fill");
  if (state.value("phase", 0) < 2) {
    SettleInfo s1;
    if (!state.contains("top_up")) {
      // When the column cannot take the whole mass, the top-up follows as soon as the column
      // factory ends, without waiting for the column to come to rest (the paper pours it all
      // from above in one go); the heap settles once, after the top-up.
      const auto short_of_mass = [&] {
        return p.heap_mass - w.factory_status(0).inserted_mass > 0.5 * mean_pill_mass(w);
      };
      s1 = pour_and_settle(c, w, "fill", {}, short_of_mass);
      const double in_tube = w.factory_status(0).inserted_mass;
      if (short_of_mass()) {
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
  RepeatResult r = heap_result(h);
  r.details.update(nlohmann::json{{"pills", w.clump_count()},
                                  {"mass_kg", w.total_mass()},
                                  {"lift_m", lift},
                                  {"lift_stop", state.value("lift_stop", "full lift")},
                                  {"settle_fill", state["settle_fill"]},
                                  {"fill", state.value("fill", nlohmann::json::object())},
                                  {"settle_heap", settle_json(s2)},
                                  {"simulated_time_s", w.time()},
                                  {"time_step_s", w.dt()},
                                  {"pinched", pinch_json(c, w)},
                                  {"profile", profile_json(c, w, c.meter.sphere_steps)}});
  if (!c.dir.empty()) heap_picture(c.dir / "heap.png", spheres, h);
  return r;
}

}  // namespace clumpkit::rigs::detail
