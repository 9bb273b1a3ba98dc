// The bulk density rig (SPEC §7): a cup filled to overflow, struck off by a moving
// scraper, weighed.
#include "procedure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "clumpkit/core/error.hpp"
#include "clumpkit/dem/world.hpp"
#include "clumpkit/rigs/geometry.hpp"

namespace clumpkit::rigs::detail {

using Eigen::Vector3d;

BulkDensityScene bulk_density_scene(const Ctx& c) {
  const ScaleParams& p = c.p;
  BulkDensityScene b;
  const std::string cup_material =
      c.req.settings.count("wall") ? c.req.settings.at("wall") : "organic_glass";
  b.cup.inner_diameter = p.cup_diameter;
  b.cup.height = p.cup_height;
  const double R = 0.5 * p.cup_diameter, H = p.cup_height;
  const std::vector<std::string> mats = {cup_material, "galvanized_steel"};

  dem::WorldSettings& ws = b.ws;
  ws = base_settings(c, mats);
  ws.source = "bulk_density rig";
  ws.walls.push_back({"cup", cup_mesh(b.cup), cup_material, {}, {}});
  ws.walls.push_back({"catch",
                      dem::make_plane(Vector3d(0, 0, -0.005), Vector3d::UnitZ(), 0.5, 0.5),
                      "galvanized_steel",
                      {},
                      {}});
  // Pour until overflow: 0.66 of the pills' own density fills the cup with margin (no pill
  // packs that densely), from a factory 5 mm above the rim (paper: D 20 mm × H 20 mm).
  b.pour_mass = 0.66 * mean_union_density(c) * b.cup.volume();
  const double fr = p.name == "paper" ? 0.010 : 0.35 * p.cup_diameter;
  const double fh = p.name == "paper" ? 0.020 : 0.6 * p.cup_height;
  ws.factories.push_back(
      pour(c, dem::CylinderRegion{Vector3d(0, 0, H + 0.005), fr, fh}, b.pour_mass));
  ws.factories.back().whole_in_region = p.pour_whole_in_region;
  // The scraper waits beside the cup; phase 2 moves it across the rim.
  b.x_start = -(R + 0.012), b.x_end = R + 0.02;
  // The blade clears the rim by a whole pill (its bounding-sphere diameter): a pill lying across
  // the rim cannot be wedged between blade and rim. Blades one sphere diameter (or less) above
  // the rim wedged such pills and the engine stopped with overlaps of 50-85 % of a radius.
  // Pills are weighed by their centre, so what the blade leaves above the rim is not counted.
  b.clearance = 2.0 * max_bound_radius(c);
  b.scraper_speed = p.scraper_speed;
  b.scraper_material = cup_material;
  ws.walls.push_back(b.scraper(1e9));
  b.scraper_wall = int(ws.walls.size()) - 1;
  return b;
}

dem::WallSettings BulkDensityScene::scraper(double t_on) const {
  const double R = 0.5 * cup.inner_diameter, H = cup.height;
  dem::WallSettings s{
      "scraper", scraper_mesh(x_start, R + 0.02, H + clearance, 0.06), scraper_material, {}, {}};
  // The blade leans back 45° (its face looks forward and up, as a grader's): the pills it meets
  // are lifted over the pile instead of being driven into the bed, where a vertical blade
  // jammed them (the engine stopped with 67-81 % overlaps).
  for (Vector3d& v : s.mesh.vertices) v.x() -= v.z() - (H + clearance);
  s.motion.translation =
      step_velocity(t_on, t_on + (x_end - x_start) / scraper_speed, Vector3d(scraper_speed, 0, 0));
  return s;
}

CupWeight weigh_cup(const std::vector<Vector3d>& centres, const std::vector<double>& masses,
                    const CupGeometry& cup) {
  CupWeight w;
  const double R = 0.5 * cup.inner_diameter, H = cup.height;
  for (size_t i = 0; i < centres.size(); ++i) {
    const Vector3d& x = centres[i];
    if (x.head<2>().norm() < R && x.z() > 0 && x.z() < H) w.mass += masses[i], ++w.pills;
  }
  return w;
}

RepeatResult bulk_density(Ctx& c) {
  const ScaleParams& p = c.p;
  BulkDensityScene b = bulk_density_scene(c);
  const dem::WorldSettings& ws = b.ws;
  const CupGeometry& cup = b.cup;
  const double R = 0.5 * p.cup_diameter, H = p.cup_height;
  const double x_start = b.x_start, x_end = b.x_end, clearance = b.clearance;
  const double pour_mass = b.pour_mass;
  const int scraper_wall = b.scraper_wall;
  auto scraper = [&](double t_on) { return b.scraper(t_on); };
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

  std::vector<double> masses;
  for (int i = 0; i < w.clump_count(); ++i) masses.push_back(w.clump_mass(i));
  const CupWeight weight = weigh_cup(w.positions(), masses, cup);
  const double mass = weight.mass;
  const long n = weight.pills;
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

}  // namespace clumpkit::rigs::detail
