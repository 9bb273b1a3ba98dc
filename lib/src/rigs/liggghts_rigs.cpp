// The rigs on LIGGGHTS (`clumpkit rig ... --engine liggghts [--np N]`): the same scene as the
// bundled runner's (bulk_density_scene, angle_of_repose_scene), the same procedure as script
// loops (pour, settle by the speed criterion, the action, settle), and the same measurement on
// what LIGGGHTS wrote (weigh_cup, measure_heap_angle).
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <numbers>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/rigs/pictures.hpp"
#include "liggghts_deck.hpp"
#include "procedure.hpp"

namespace clumpkit::rigs::detail {

namespace fs = std::filesystem;
using Eigen::Vector3d;

namespace {

// The bundled runner's explicit time step for these settings (LIGGGHTS has no implicit
// damping, so the step must keep the stiffest contact's damping explicit-stable).
double explicit_time_step(const dem::WorldSettings& ws) {
  dem::WorldSettings s = ws;
  s.implicit_damping = 0.0;
  s.threads = 1;
  return dem::World::create(s).dt();
}

// The mean mass of the pills a LIGGGHTS insertion of this factory's mixture places: its
// fractions are mass fractions, so the pills come in number fractions w_i / m_i, normalised.
// LIGGGHTS places floor(mass asked / this) of them.
double expected_pill_mass(const dem::WorldSettings& ws, const dem::FactorySettings& f) {
  double fractions = 0, per_kg = 0;
  for (const auto& e : f.mixture)
    for (const auto& t : ws.clump_types)
      if (t.name == e.clump_type) {
        fractions += e.mass_fraction;
        per_kg += e.mass_fraction / t.clump.mass.mass;
      }
  return fractions / per_kg;
}

double lightest_pill(const dem::WorldSettings& ws) {
  double m = 0;
  for (const auto& t : ws.clump_types)
    m = m == 0 ? t.clump.mass.mass : std::min(m, t.clump.mass.mass);
  return m;
}

Eigen::AlignedBox3d walls_box(const dem::WorldSettings& ws) {
  Eigen::AlignedBox3d box;
  for (const auto& w : ws.walls)
    for (const Vector3d& v : w.mesh.vertices) box.extend(v);
  return box;
}

void extend(Eigen::AlignedBox3d& box, const dem::Region& r) {
  if (const auto* c = std::get_if<dem::CylinderRegion>(&r)) {
    box.extend(c->base_center - Vector3d(c->radius, c->radius, 0));
    box.extend(c->base_center + Vector3d(c->radius, c->radius, c->height));
  } else {
    box.extend(std::get<dem::BoxRegion>(r).min);
    box.extend(std::get<dem::BoxRegion>(r).max);
  }
}

// The clumps of a `write_bodies` dump: centres of mass and masses (and the dump's step).
struct Bodies {
  std::vector<Vector3d> centres;
  std::vector<double> masses;
  long step = 0;
};
Bodies read_bodies(const fs::path& file) {
  Bodies b;
  for (const auto& row : read_dump_rows(file.string(), 4, &b.step)) {
    b.centres.emplace_back(row[0], row[1], row[2]);
    b.masses.push_back(row[3]);
  }
  return b;
}

// The catch plate below a rig need only reach past its outlet: the domain is sized on it.
void shrink_catch(dem::WorldSettings& ws, const dem::TriangleMesh& plate) {
  for (auto& w : ws.walls)
    if (w.name == "catch") w.mesh = plate;
}

// The folder the deck runs in: the repeat's `liggghts/`, or a temporary one removed afterwards.
struct RunFolder {
  fs::path dir;
  bool temporary = false;
  explicit RunFolder(const Ctx& c) {
    if (!c.dir.empty()) {
      dir = c.dir / "liggghts";
    } else {
      dir = fs::temp_directory_path() / fmt::format("clumpkit_liggghts_{}_{}", ::getpid(), c.seed);
      temporary = true;
    }
    std::error_code ec;
    fs::remove_all(dir, ec);  // a killed run starts its repeat again
    fs::create_directories(dir);
  }
  ~RunFolder() {
    std::error_code ec;
    if (temporary) fs::remove_all(dir, ec);
  }
  RunFolder(const RunFolder&) = delete;
  RunFolder& operator=(const RunFolder&) = delete;
};

// Writes the deck, runs it, and returns LIGGGHTS's wall time, s.
double run_deck(Ctx& c, const LiggghtsDeck& deck, const fs::path& dir) {
  for (const DeckFile& f : deck.files()) write_file_atomic(dir / f.name, f.content);
  const int np = std::max(1, c.req.liggghts_ranks);
  c.say(fmt::format("LIGGGHTS deck written to {}; running it on {} MPI rank{}", dir.string(), np,
                    np > 1 ? "s" : ""));
  for (const auto& n : deck.notes()) c.say("note: " + n);
  const auto t0 = Clock::now();
  run_liggghts(dir.string(), np,
               [&](const std::string& s) { c.progress([&] { return "liggghts: " + s; }); });
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

nlohmann::json engine_json(const Ctx& c, const LiggghtsDeck& deck, const fs::path& dir,
                           const RunFolder& folder, double seconds) {
  return {{"engine", "liggghts"},
          {"mpi_ranks", std::max(1, c.req.liggghts_ranks)},
          {"deck", folder.temporary ? std::string() : (dir / "in.rig").string()},
          {"liggghts_wall_seconds", seconds},
          {"time_step_s", deck.dt()},
          {"differences", deck.notes()}};
}

RepeatResult liggghts_bulk_density(Ctx& c) {
  const ScaleParams& p = c.p;
  BulkDensityScene b = bulk_density_scene(c);
  const double R = 0.5 * b.cup.inner_diameter;
  shrink_catch(b.ws, dem::make_plane(Vector3d(0, 0, -0.005), Vector3d::UnitZ(), 2 * (R + 0.03),
                                     2 * (R + 0.03)));
  Eigen::AlignedBox3d box = walls_box(b.ws);
  for (const Vector3d& v : b.ws.walls[size_t(b.scraper_wall)].mesh.vertices)
    box.extend(v + Vector3d(b.x_end - b.x_start, 0, 0));
  for (const auto& f : b.ws.factories) extend(box, f.region);
  box.min() -= Vector3d(0.005, 0.005, 0.01);
  box.max() += Vector3d(0.005, 0.005, 0.01);

  const RunFolder folder(c);
  const fs::path& dir = folder.dir;
  LiggghtsDeck deck(b.ws, box, 0.0, explicit_time_step(b.ws), c.seed,
                    fmt::format("clumpkit rig bulk_density, model {}, scale {}, seed {}",
                                c.req.model.name, p.name, c.seed));
  deck.run(deck.insert(b.ws.factories[0]), "pour");
  deck.finish_insertion(0.5 * lightest_pill(b.ws));
  deck.settle("pour: settling", p.settle_speed, p.settle_max);
  deck.line("variable top equal bound(all,zmax)");
  deck.line("print \"clumpkit: poured, bed top (highest sphere centre) ${top} m\"");
  deck.move_wall("scraper", Vector3d(b.scraper_speed, 0, 0));
  deck.run((b.x_end - b.x_start) / b.scraper_speed, "strike-off");
  deck.stop_wall("scraper");
  deck.settle("after strike-off", p.settle_speed, p.settle_max);
  deck.write_state("bodies.txt", "spheres.txt");
  const double seconds = run_deck(c, deck, dir);

  const Bodies bodies = read_bodies(dir / "bodies.txt");
  double total = 0;
  for (double m : bodies.masses) total += m;
  const CupWeight weight = weigh_cup(bodies.centres, bodies.masses, b.cup);
  RepeatResult r;
  r.values["bulk_density"] = weight.mass / b.cup.volume();
  r.details = {{"mass_kg", weight.mass},          {"pills", weight.pills},
               {"cup_volume_m3", b.cup.volume()}, {"poured_mass_kg", b.pour_mass},
               {"mass_in_domain_kg", total},      {"blade_clearance_m", b.clearance}};
  r.details.update(engine_json(c, deck, dir, folder, seconds));
  return r;
}

RepeatResult liggghts_angle_of_repose(Ctx& c) {
  const ScaleParams& p = c.p;
  AngleOfReposeScene a = angle_of_repose_scene(c);
  const double H = a.g.height;
  // The tube rises by at most the bed's height (the tube's) plus a pill and 1 cm.
  Eigen::AlignedBox3d box = walls_box(a.ws);
  box.extend(Vector3d(0, 0, 2 * H + 2 * a.br + 0.03));
  for (const auto& f : a.ws.factories) extend(box, f.region);
  box.min() -= Vector3d(0.005, 0.005, 0.03);
  box.max() += Vector3d(0.005, 0.005, 0.01);

  const RunFolder folder(c);
  const fs::path& dir = folder.dir;
  LiggghtsDeck deck(a.ws, box, -0.02, explicit_time_step(a.ws), c.seed,
                    fmt::format("clumpkit rig angle_of_repose, model {}, scale {}, seed {}",
                                c.req.model.name, p.name, c.seed));
  const dem::FactorySettings& fill = a.ws.factories[0];
  // Half the lightest pill: the tolerance on the mass poured.
  const double pill_mass = lightest_pill(a.ws);
  deck.run(deck.insert(fill), "fill");
  const std::string in_column = deck.finish_insertion(0.5 * pill_mass);
  // What the column could not hold is poured from above its top (the paper's region), as the
  // bundled runner does; the heap settles once, after it.
  deck.line(fmt::format("variable short equal {}-${{{}}}", p.heap_mass, in_column));
  const dem::FactorySettings top = a.top_up(0.0, p.heap_mass);
  const double m_pill = expected_pill_mass(a.ws, top);
  deck.begin_block();
  deck.line("print \"clumpkit: the tube holds less than asked: pouring ${short} kg from above\"");
  // LIGGGHTS places floor(mass / mean pill mass) pills, and an insertion of none stops the next
  // run ("'start' step can not be before current step"; found with a 0.57-pill shortfall). The
  // block runs for a shortfall above half a mean pill, as the bundled runner's top-up does, so
  // the shortfall plus half a pill (a hair more, for LIGGGHTS's rounding of the templates'
  // masses) is the nearest whole number of pills and at least one.
  deck.line(fmt::format("variable top_kg equal ${{short}}+{:.12g}", (0.5 + 1e-6) * m_pill));
  const double interval = deck.insert(top, "top_kg") - *top.mass / top.rate;
  deck.run(fmt::format("{:.10g}+${{top_kg}}/{:.10g}", interval, top.rate), "top-up");
  deck.finish_insertion(0.5 * pill_mass);
  deck.end_block("top_up.in", fmt::format("${{short}} > {:.12g}", 0.5 * m_pill));
  deck.settle("fill: settling", p.settle_speed, p.settle_max);
  deck.line("variable top equal bound(all,zmax)");
  deck.line(fmt::format("variable lift equal ${{top}}+{}", a.br + 0.01));
  deck.line("print \"clumpkit: filled, lifting the tube ${lift} m\"");
  deck.move_wall("tube", Vector3d(0, 0, p.lift_speed));
  deck.run(fmt::format("${{lift}}/{}", p.lift_speed), "lifting");
  deck.stop_wall("tube");
  deck.settle("heap flow", p.settle_speed, p.settle_max);
  deck.write_state("bodies.txt", "spheres.txt");
  const double seconds = run_deck(c, deck, dir);

  Spheres spheres;
  for (const auto& row : read_dump_rows((dir / "spheres.txt").string(), 5))
    if (row[3] > -0.02) spheres.push_back({Vector3d(row[1], row[2], row[3]), row[4]});
  double mass = 0;
  long pills = 0;
  const Bodies bodies = read_bodies(dir / "bodies.txt");
  for (size_t i = 0; i < bodies.masses.size(); ++i)
    if (bodies.centres[i].z() > -0.02) mass += bodies.masses[i], ++pills;
  const HeapAngle h = measure_heap_angle(spheres);
  RepeatResult r = heap_result(h);
  r.details.update(nlohmann::json{{"pills", pills}, {"mass_kg", mass}, {"lift_stop", "full lift"}});
  r.details.update(engine_json(c, deck, dir, folder, seconds));
  if (!c.dir.empty()) heap_picture(c.dir / "heap.png", spheres, h);
  return r;
}

RepeatResult liggghts_discharge(Ctx& c) {
  const ScaleParams& p = c.p;
  DischargeScene d = discharge_scene(c);
  const WheelGeometry& g = d.g;
  const double half = g.outer_radius + g.housing_gap + 0.05;
  shrink_catch(d.ws, dem::make_plane(Vector3d(0, 0, d.z_out - 0.06), Vector3d::UnitZ(), 2 * half,
                                     g.length + 0.01));
  Eigen::AlignedBox3d box = walls_box(d.ws);
  // The turning wheel sweeps its outer circle.
  const double ro = g.outer_radius + 0.001;
  box.extend(Vector3d(-ro, 0, g.axis_height - ro));
  box.extend(Vector3d(ro, 0, g.axis_height + ro));
  for (const auto& f : d.ws.factories) extend(box, f.region);
  box.min() -= Vector3d(0.005, 0.005, 0.02);
  box.max() += Vector3d(0.005, 0.005, 0.01);

  const RunFolder folder(c);
  const fs::path& dir = folder.dir;
  LiggghtsDeck deck(d.ws, box, d.z_out, explicit_time_step(d.ws), c.seed,
                    fmt::format("clumpkit rig discharge, model {}, scale {}, {} rpm, seed {}",
                                c.req.model.name, p.name, p.rpm, c.seed));
  const double dt = deck.dt();
  deck.run(deck.insert(d.ws.factories[0]), "filling the hopper");
  deck.finish_insertion(0.5 * lightest_pill(d.ws));
  deck.settle("hopper: settling", p.settle_speed, p.settle_max);
  // As the bundled runner: the wheel starts 10 ms after the bed has come to rest (t0); the
  // discharged mass is sampled every tenth of a pocket period from the settle on, and each
  // counted pocket weighed a twentieth of a period after it has closed.
  const PocketSchedule sched = pocket_schedule(g, p, 0.0);
  const int need = p.pockets_skipped + p.pockets_measured;
  const double sample = sched.period / 10.0;
  struct Event {
    double t;    // s after t0
    int pocket;  // -1: a sample of the discharged mass
  };
  std::vector<Event> events;
  for (double t = -0.01; t <= sched.t_end + 1e-12; t += sample) events.push_back({t, -1});
  for (int k = 0; k < need; ++k)
    events.push_back({sched.pockets[size_t(k)].t_close + sched.settle_delay, k});
  std::stable_sort(events.begin(), events.end(),
                   [](const Event& a, const Event& b) { return a.t < b.t; });
  const long start_steps = long(std::ceil(0.01 / dt - 1e-9));
  long at = 0;  // steps after the settle
  bool turning = false;
  for (size_t e = 0; e < events.size(); ++e) {
    const long to = std::max(at, long(std::ceil((events[e].t + 0.01) / dt - 1e-9)));
    if (!turning && to >= start_steps) {
      if (start_steps > at) deck.line(fmt::format("run {}", start_steps - at));
      at = start_steps;
      deck.rotate_wall("wheel", Vector3d(0, 0, g.axis_height), Vector3d::UnitY(), p.rpm);
      turning = true;
    }
    if (to > at) deck.line(fmt::format("run {}", to - at));
    at = to;
    deck.write_bodies(fmt::format("event_{}.txt", e));
    deck.line(fmt::format("print \"clumpkit: discharge: t = ${{now}} s, {} of {} pockets weighed\"",
                          events[e].pocket >= 0 ? events[e].pocket + 1 : 0, need));
  }
  const double seconds = run_deck(c, deck, dir);

  // Steps count from 0 at a constant step, so a dump's time is its step times dt.
  double t0 = 0;   // s, the wheel's start: start_steps after the first sample
  double up0 = 0;  // mass in the rig (centre above z_out) when the first sample was taken
  long pills = 0;  // clumps in the rig at the last event
  std::vector<double> fills, curve_t, curve_m;
  for (size_t e = 0; e < events.size(); ++e) {
    const Bodies b = read_bodies(dir / fmt::format("event_{}.txt", e));
    double up = 0;
    pills = 0;
    for (size_t i = 0; i < b.masses.size(); ++i)
      if (b.centres[i].z() >= d.z_out) up += b.masses[i], ++pills;
    const long step = b.step;
    if (e == 0) t0 = double(step + start_steps) * dt;
    const double t = double(step) * dt;
    if (e == 0) up0 = up;
    if (events[e].pocket < 0) {
      curve_t.push_back(t - t0);
      curve_m.push_back(up0 - up);
    } else {
      const int k = sched.pockets[size_t(events[e].pocket)].k;
      const double lower = k * sched.pitch - sched.omega * (t - t0);
      const double m = pocket_mass(b.centres, b.masses, g, lower);
      if (events[e].pocket >= p.pockets_skipped) fills.push_back(m);
      c.say(fmt::format("pocket {} weighed at t = {:.3f} s: {:.4f} kg in the slice",
                        events[e].pocket + 1, t, m));
    }
  }
  RepeatResult r = discharge_result(p, g, fills, curve_t, curve_m);
  r.details["pills"] = pills;
  r.details.update(engine_json(c, deck, dir, folder, seconds));
  if (!c.dir.empty())
    curve_picture(c.dir / "discharge.png", {{fmt::format("{:g} rpm", p.rpm), curve_t, curve_m}},
                  "t s", "m kg");
  return r;
}

}  // namespace

RepeatResult liggghts_repeat(Ctx& c) {
  if (c.req.rig == "bulk_density") return liggghts_bulk_density(c);
  if (c.req.rig == "angle_of_repose") return liggghts_angle_of_repose(c);
  return liggghts_discharge(c);
}

}  // namespace clumpkit::rigs::detail
