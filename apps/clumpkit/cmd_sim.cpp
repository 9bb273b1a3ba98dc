// clumpkit sim SCENE [--until T] [--threads N] [--out DIR] | clumpkit sim --resume DIR
#ifdef CLUMPKIT_HAVE_SIM
#include <fmt/format.h>

#include <iostream>

#include "cli_util.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/core/units.hpp"
#include "clumpkit/sim/runner.hpp"

namespace clumpkit::cli {
namespace {

struct SimArgs {
  std::string scene, until, out = "sim_out", resume;
  int threads = 0;
  bool quiet = false;
};

int report(const sim::RunSummary& s, const std::string& out) {
  std::cout << fmt::format(
      "{} at t = {:.6g} s after {} steps in {:.1f} s wall time ({} clumps, {} spheres)\n",
      s.interrupted ? "interrupted" : "finished", s.time, s.steps, s.wall_seconds, s.clumps,
      s.spheres);
  std::cout << fmt::format("state hash {:016x}\n", s.state_hash);
  if (s.interrupted) {
    std::cout << "checkpoint written; continue with: clumpkit sim --resume " << out << "\n";
    return 130;
  }
  std::cout << "time per stage:\n" << s.profile.table();
  if (s.profile.steps > 0 && s.spheres > 0)
    std::cout << fmt::format("{:.3g} sphere-steps/s, {:.3g} clump-steps/s\n",
                             static_cast<double>(s.spheres) * s.profile.steps / s.profile.total(),
                             static_cast<double>(s.clumps) * s.profile.steps / s.profile.total());
  std::cout << "outputs in " << out << "/ (series.csv, particles.pvd, walls.pvd, profile.txt)\n";
  return 0;
}

Command setup_sim(CLI::App& parent) {
  auto a = std::make_shared<SimArgs>();
  CLI::App* c = parent.add_subcommand(
      "sim",
      "Run a DEM scene file (clumps, materials, walls, factories) with VTK/CSV output, "
      "progress, checkpoints; --resume continues a killed run");
  c->add_option("SCENE", a->scene, "Scene file (.toml, see docs/scene_format.md)");
  c->add_option("--until", a->until,
                "Simulated end time with unit, e.g. \"0.5 s\" (default: "
                "the scene's)");
  c->add_option("--threads", a->threads, "Threads (default: the scene's, else all cores)")
      ->check(CLI::Range(1, 256));
  c->add_option("--out", a->out, "Output folder");
  c->add_option("--resume", a->resume,
                "Continue the run in this output folder from its last "
                "checkpoint");
  c->add_flag("--quiet", a->quiet, "No progress lines");
  return {c, [a] {
            sim::install_stop_handlers();
            if (!a->resume.empty()) {
              if (!a->scene.empty())
                throw InputError("", "SCENE", "give either a scene or --resume DIR, not both");
              return report(sim::resume_run(a->resume, data_dir(), !a->quiet), a->resume);
            }
            if (a->scene.empty()) throw InputError("", "SCENE", "a scene file is required");
            const sim::Scene scene = sim::load_scene(a->scene, data_dir());
            sim::RunOptions o;
            o.out = a->out;
            o.threads = a->threads;
            o.progress = !a->quiet;
            if (!a->until.empty())
              o.until = parse_quantity(a->until, Dimension::Time, "", "--until");
            return report(sim::run_scene(scene, o), a->out);
          }};
}

const Registration reg_sim(50, setup_sim);

}  // namespace
}  // namespace clumpkit::cli
#endif
