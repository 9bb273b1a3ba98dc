// clumpkit rig: run one of the paper's validation rigs with a particle model (SPEC §7).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cstdint>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "cli_util.hpp"
#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/rigs/catalogue.hpp"
#include "clumpkit/rigs/geometry.hpp"
#include "clumpkit/rigs/model.hpp"
#include "clumpkit/rigs/rig.hpp"

namespace clumpkit::cli {
namespace {

namespace fs = std::filesystem;

struct RigArgs {
  std::string rig, model = "production", scale, json, out, meshes;
  int repeats = 1;
  std::uint64_t seed = 1;
  std::vector<std::string> sets;
  bool vtk = false, list = false;
  int threads = 0;
  long rays = 20000;
  double checkpoint_interval = 60.0;
  std::string bed_from;
  std::string engine = "clumpkit";
  int np = 1;
};

// --bed-from: only for the discharge rig, a folder holding every repeat's bed (whether a bed fits
// this run's model, scale and seed is checked as each repeat takes it).
fs::path checked_bed_from(const RigArgs& a, const RigInfo& info) {
  if (a.bed_from.empty()) return {};
  if (info.name != "discharge")
    throw InputError("--bed-from", a.bed_from, "only the discharge rig turns a saved bed");
  if (!fs::is_directory(a.bed_from)) throw InputError("--bed-from", a.bed_from, "is not a folder");
  for (int k = 1; k <= a.repeats; ++k) rigs::require_bed(a.bed_from, k);
  return a.bed_from;
}

void list_rigs() {
  for (const auto& r : rig_catalogue()) {
    std::cout << fmt::format("{}: {}\n  quantities:", r.name, r.description);
    for (const auto& q : r.quantities) std::cout << fmt::format(" {} ({})", q.name, q.unit);
    std::cout << "\n  settings (--set key=value):\n";
    for (const auto& s : r.settings) {
      std::string v = s.choices.empty() ? s.unit : "";
      for (const auto& c : s.choices) v += (v.empty() ? "" : "|") + c;
      std::cout << fmt::format("    {:<11} {:<36} default {:<8} {}\n", s.key, v, s.default_value,
                               s.description);
    }
  }
  std::cout << "model effects (--set effects.NAME[.PARTNER]=VALUE|on|off):";
  for (const auto& e : effect_names()) std::cout << " " << e;
  std::cout << "\n  e.g. effects.rolling_friction.pill=0.1, effects.cohesion=\"2e4 J/m^3\", "
               "effects.shape_resolution=4, effects.size_distribution=0.05 (height spread), "
               "effects.rolling_model=cdt, effects.restitution=off\n";
}

Command setup_rig(CLI::App& parent) {
  auto a = std::make_shared<RigArgs>();
  CLI::App* c = parent.add_subcommand(
      "rig",
      "Run a validation rig (bulk_density, angle_of_repose, discharge) with a particle "
      "model through the DEM engine; repeats give mean and standard deviation (SI units)");
  c->add_option("name", a->rig, "Rig: bulk_density | angle_of_repose | discharge");
  c->add_option("--model", a->model,
                "Particle model: a file or a bundled name (shapes/models/: production, "
                "paper_A12, ...)")
      ->capture_default_str();
  c->add_option("--scale", a->scale,
                "tiny (smoke tests) | mini (quick) | small | paper (the paper's sizes)");
  c->add_option("--repeats", a->repeats, "Repeats with seeds seed, seed+1, ...")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  c->add_option("--seed", a->seed, "Seed of the first repeat")->capture_default_str();
  c->add_option("--set", a->sets,
                "key=value: a rig setting (see --list; e.g. rpm=30, plate=abs_plastic, "
                "lift_speed=200) or a model effect (effects.rolling_friction.pill=0.1, "
                "effects.cohesion=\"2e4 J/m^3\", effects.restitution=off, "
                "effects.size_distribution.B=0.5: type B's mass fraction)");
  c->add_option("--json", a->json, "Write the result as JSON (FILE or -)");
  c->add_option("--out", a->out,
                "Folder for checkpoints, per-repeat results and pictures (a rerun resumes and "
                "keeps finished repeats)");
  c->add_flag("--vtk", a->vtk, "Also write VTK (.vtp) snapshots of spheres and walls to --out");
  c->add_option("--threads", a->threads, "Threads (0 = all)")->check(CLI::NonNegativeNumber);
  c->add_option("--rays", a->rays, "Rays for the clumps' mass properties")
      ->check(CLI::PositiveNumber);
  c->add_option("--checkpoint-interval", a->checkpoint_interval,
                "Wall-clock seconds between checkpoints in --out (a killed run resumes from the "
                "last one)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  c->add_option("--bed-from", a->bed_from,
                "discharge: turn the beds of an earlier run (its --out folder) at this run's "
                "rpm instead of filling the hopper again, as the paper turned one bed at 10, 15 "
                "and 30 rpm (same model, scale, seeds; the earlier run needs --out)");
  c->add_option("--engine", a->engine,
                "clumpkit (the bundled runner) | liggghts: the rig written as a LIGGGHTS 3.8 "
                "deck (the same walls, templates, laws and procedure) and run there, for runs "
                "that outgrow one machine; the deck stays in --out/repeat_K/liggghts/")
      ->check(CLI::IsMember({"clumpkit", "liggghts"}))
      ->capture_default_str();
  c->add_option("--np", a->np, "--engine liggghts: MPI ranks (mpirun -np N; 1 = no mpirun)")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  c->add_flag("--list", a->list, "List the rigs, their quantities, settings and the effects");
  c->add_option("--write-meshes", a->meshes,
                "Write the rigs' wall meshes (paper size, STL in metres) to this folder and exit");
  return {c, [a] {
            if (a->list) {
              list_rigs();
              return 0;
            }
            if (!a->meshes.empty()) {
              for (const auto& n : rigs::write_rig_meshes(a->meshes))
                std::cout << (fs::path(a->meshes) / n).string() << "\n";
              return 0;
            }
            if (a->rig.empty()) throw InputError("", "name", "give a rig name (see --list)");
            const RigInfo& info = find_rig(a->rig, "", "rig");
            rigs::RigRequest req;
            req.rig = info.name;
            req.model = load_model(find_model(a->model), data_dir());
            std::string settings = a->scale.empty() ? "" : "scale=" + a->scale;
            for (const auto& s : a->sets) {
              const auto eq = s.find('=');
              if (eq == std::string::npos) throw InputError("--set", s, "expected key=value");
              const std::string key = s.substr(0, eq), value = s.substr(eq + 1);
              if (key.rfind("effects.", 0) == 0)
                set_model_effect(req.model, key, value, "--set");
              else
                settings += (settings.empty() ? "" : ";") + s;
            }
            req.settings = parse_settings(info, settings, "--set", "");
            if (!req.settings.count("scale")) req.settings["scale"] = "mini";
            req.repeats = a->repeats;
            req.seed = a->seed;
            req.vtk = a->vtk;
            req.threads = a->threads;
            req.rays = a->rays;
            req.checkpoint_interval = a->checkpoint_interval;
            if (a->engine == "liggghts" && !a->bed_from.empty())
              throw InputError("--bed-from", a->bed_from,
                               "not with --engine liggghts (a LIGGGHTS run fills its own "
                               "hopper; the saved beds are the bundled runner's checkpoints)");
            req.bed_from = checked_bed_from(*a, info);
            req.engine = a->engine;
            req.liggghts_ranks = a->np;
            rigs::check_engine(a->engine, a->np);  // before the templates are built
            if (a->engine == "liggghts" && a->vtk)
              throw InputError("--vtk", "",
                               "not with --engine liggghts (its dumps are in "
                               "--out/repeat_K/liggghts/)");
            if (a->vtk && a->out.empty())
              throw InputError("--vtk", "", "VTK output needs --out DIR");
            // Scale parameters are checked before anything is written or the long run starts.
            (void)rigs::rig_scale(req.rig, req.settings);
            std::optional<OutputFolder> out_folder;  // gone again if the run writes nothing
            if (!a->out.empty()) {
              out_folder.emplace(a->out, "--out");
              req.out = a->out;
            }
            if (!a->json.empty() && a->json != "-") check_writable(a->json, "--json");
            req.progress = [](const std::string& s) { std::cerr << s << std::endl; };

            const rigs::RigResult r = rigs::run_rig(req);
            std::cout << fmt::format("{} with model {} at scale {} ({}), {} repeat(s)\n", r.rig,
                                     r.model, r.scale, format_settings(r.settings),
                                     r.repeats.size());
            if (r.repeats.empty())
              std::cout << "no repeat finished\n";
            else
              std::cout << fmt::format("{:<16} {:>12} {:>12} {:>3}  {}\n", "quantity", "mean",
                                       "std", "n", "unit");
            for (const auto& q : info.quantities) {
              const auto it = r.stats.find(q.name);
              if (it == r.stats.end()) continue;
              std::cout << fmt::format("{:<16} {:>12.5g} {:>12.5g} {:>3}  {}\n", q.name,
                                       it->second.mean / q.to_si, it->second.std / q.to_si,
                                       it->second.n, q.unit);
            }
            for (const auto& rep : r.repeats) {
              // A repeat run again after a jam (rigs::detail::run_attempts) says so.
              std::string retried;
              if (const auto j = rep.details.find("jammed"); j != rep.details.end()) {
                std::vector<std::uint64_t> seeds;
                for (const auto& e : *j) seeds.push_back(e.at("seed").get<std::uint64_t>());
                retried = fmt::format(", the wheel jammed with seed{} {}",
                                      seeds.size() == 1 ? "" : "s", fmt::join(seeds, ", "));
                if (rep.details.contains("seed_used"))
                  retried += fmt::format(" and flowed with {}",
                                         rep.details.at("seed_used").get<std::uint64_t>());
              }
              std::cout << fmt::format("  seed {}: {:.1f} s wall{}{}\n", rep.seed, rep.wall_seconds,
                                       retried, rep.resumed ? " (kept from an earlier run)" : "");
            }
            if (!a->json.empty()) write_json(r.to_json(), a->json);
            if (!r.error.empty()) {
              std::cerr << "clumpkit rig: " << r.error
                        << (r.repeats.empty() ? "" : " (finished repeats kept)") << std::endl;
              return 2;
            }
            return 0;
          }};
}

const Registration reg_rig(40, setup_rig);

}  // namespace
}  // namespace clumpkit::cli
