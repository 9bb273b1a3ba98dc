// Benchmark (not a test): a pour of 12-sphere pills (paper models A, B, C, mass fractions
// 35/35/30 %) from a cylinder factory into an organic-glass cup, with the per-stage profile.
//
//   dem_bench [pills=300] [threads=2] [sim_time_s=0.25] [skin_m=default]
//
// Prints sphere-steps/s and clump-steps/s over the whole run (wall clock of World::step).
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "clumpkit/dem/world.hpp"
#include "clumpkit/fill/paper_fill.hpp"

using namespace clumpkit;

int main(int argc, char** argv) {
  const long pills = argc > 1 ? std::atol(argv[1]) : 300;
  const int threads = argc > 2 ? std::atoi(argv[2]) : 2;
  const double until = argc > 3 ? std::atof(argv[3]) : 0.25;
  const double skin = argc > 4 ? std::atof(argv[4]) : 0.0;  // m, 0 = the default

  dem::WorldSettings s;
  s.source = "dem_bench";
  s.threads = threads;
  s.skin = skin;
  const struct {
    const char* name;
    double height, fraction;
  } kinds[] = {{"A12", 5.4e-3, 0.35}, {"B12", 5.8e-3, 0.35}, {"C12", 6.2e-3, 0.30}};
  PaperFillRequest req;
  req.spheres = 12;
  req.sampling.rays = 200'000;
  dem::FactorySettings f;
  for (const auto& k : kinds) {
    dem::ClumpTypeSettings t;
    t.name = k.name;
    t.clump = paper_fill_template(cylinder_shape(k.name, 6.0e-3, k.height, 1380.0), req);
    s.clump_types.push_back(t);
    f.mixture.push_back({k.name, k.fraction});
  }
  // Cup: 300 pills fill about 2/3 of it; larger pours scale it in proportion.
  const double scale = std::cbrt(std::max(1.0, pills / 300.0));
  const double cup_r = 0.025 * scale, cup_h = 0.06 * scale;
  s.walls.push_back({"cup",
                     dem::make_cylinder(Eigen::Vector3d::Zero(), cup_r, cup_h, 48, true, false),
                     "organic_glass",
                     {},
                     {}});
  f.name = "pour";
  f.region = dem::CylinderRegion{Eigen::Vector3d(0, 0, cup_h + 0.005), cup_r * 0.9, 0.03};
  f.count = pills;
  f.rate = pills / 0.15;  // poured over 0.15 s in batches every 10 ms
  f.interval = 0.01;
  f.velocity = Eigen::Vector3d(0, 0, -0.5);
  s.factories.push_back(f);
  s.max_impact_speed = 1.5;

  dem::World w = dem::World::create(s);
  for (const auto& msg : w.warnings()) std::printf("warning: %s\n", msg.c_str());
  std::printf("%ld pills poured over 0.15 s, dt %.3g s, %d thread(s), until %.3g s\n", pills,
              w.dt(), threads, until);
  const auto t0 = std::chrono::steady_clock::now();
  long sphere_steps = 0, clump_steps = 0;
  while (w.time() < until) {
    w.step();
    sphere_steps += w.sphere_count();
    clump_steps += w.clump_count();
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%ld steps in %.2f s: %.3g sphere-steps/s, %.3g clump-steps/s\n", w.step_count(),
              wall, sphere_steps / wall, clump_steps / wall);
  std::printf("%d pills, %ld spheres; contacts %d, kinetic energy %.3g J, state hash %016llx\n",
              w.clump_count(), w.sphere_count(), w.contact_count(), w.kinetic_energy(),
              static_cast<unsigned long long>(w.state_hash()));
  std::printf("%s", w.profile().table().c_str());
  return 0;
}
