// clumpkit compare / diagnose / synth: the model against measurements (issue: compare, diagnose,
// add the missing effect, watch the error fall).
#ifdef CLUMPKIT_HAVE_CALIBRATE
#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <optional>
#include <random>
#include <set>
#include <thread>

#include "cli_util.hpp"
#include "clumpkit/calibrate/diagnosis.hpp"
#include "clumpkit/calibrate/model_writer.hpp"
#include "clumpkit/calibrate/report.hpp"
#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/rigs/rig.hpp"

namespace clumpkit::cli {
namespace {

using namespace clumpkit::calibrate;
using nlohmann::json;

struct CalArgs {
  std::vector<std::string> models;
  std::string measurements, scale = "mini", json, report, cache = "clumpkit_cache", output;
  std::string effects;
  int repeats = 2, threads = 0, jobs = 0, screen_repeats = 1, end_runs = 2;
  std::uint64_t seed = 1;
  bool apply = false, quiet = false, no_suggest = false, no_pairs = false;
  std::string suggest = "ambiguous";
  double noise = 0.03;
  std::string engine = "clumpkit";
  int np = 1;
};

void common_options(CLI::App* c, CalArgs& a) {
  c->add_option("--scale", a.scale, "Rig scale: tiny | mini | small | paper")
      ->check(CLI::IsMember({"tiny", "mini", "small", "paper"}))
      ->capture_default_str();
  c->add_option("--repeats", a.repeats, "Simulation repeats (different seeds) per rig setting")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  c->add_option("--seed", a.seed, "Seed of the first repeat")->capture_default_str();
  c->add_option("--cache", a.cache, "Folder of cached rig results (nothing is simulated twice)")
      ->capture_default_str();
  c->add_option("--threads", a.threads, "Engine threads per rig run (0 = the engine's choice)");
  c->add_option("--jobs", a.jobs,
                "Rig runs made side by side, each repeat apart, one engine thread each (0 = one "
                "per core at the tiny and mini scales, 1 at small and paper)")
      ->check(CLI::Range(0, 256));
  c->add_option("--engine", a.engine,
                "clumpkit (the bundled runner) | liggghts: every rig run written as a LIGGGHTS "
                "3.8 deck and run there (`clumpkit rig --engine liggghts`), for rigs that "
                "outgrow one machine; cached apart from the bundled runner's results")
      ->check(CLI::IsMember({"clumpkit", "liggghts"}))
      ->capture_default_str();
  c->add_option("--np", a.np,
                "--engine liggghts: MPI ranks per rig run (mpirun -np N; 1 = no mpirun). "
                "--jobs then defaults to the cores over N")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  c->add_option("--json", a.json, "Write the result as JSON (FILE or -)");
  c->add_flag("--quiet", a.quiet, "No progress lines");
}

// MPI ranks per rig run, as the JSON reports them (0: the bundled runner).
int mpi_ranks(const CalArgs& a) {
  return a.engine == "liggghts" ? a.np : 0;
}

RigSimulator make_sim(const CalArgs& a) {
  RigSimulator::Options o;
  o.cache_dir = a.cache;
  o.threads = a.threads;
  o.engine = a.engine;
  o.liggghts_ranks = a.np;
  // Side by side at the small scales: one engine thread, or one run of N MPI ranks, per core.
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  o.jobs = a.jobs > 0                                 ? a.jobs
           : (a.scale == "tiny" || a.scale == "mini") ? std::max(1, cores / a.np)
                                                      : 1;
  if (!a.quiet) o.progress = [](const std::string& s) { std::cerr << "clumpkit: " << s << "\n"; };
  return RigSimulator(o);
}

json comparison_json(const Comparison& c) {
  json obs = json::array();
  for (const auto& o : c.observables)
    obs.push_back({{"rig", o.measured.rig},
                   {"sample", o.measured.sample},
                   {"setting", o.measured.setting_text()},
                   {"quantity", o.measured.quantity},
                   {"unit", o.measured.unit},
                   {"measured", o.measured.value},
                   {"measured_std", o.measured.std},
                   {"measured_n", o.measured.n},
                   {"simulated", o.simulated.mean},
                   {"simulated_std", o.simulated.std},
                   {"simulated_n", o.simulated.n},
                   {"difference", o.difference},
                   {"z", o.z},
                   {"rel_error", o.rel_error},
                   {"pass", o.pass}});
  return {{"observables", obs}, {"chi2", c.chi2}, {"dof", c.dof}, {"chi2_per_dof", c.chi2_per_dof}};
}

void print_comparison(const std::string& model, const Comparison& c) {
  std::cout << fmt::format("model {}\n", model);
  std::cout << fmt::format("{:<16} {:<4} {:<26} {:<15} {:>10} {:>9} {:>10} {:>9} {:>7} {:>8} {}\n",
                           "rig", "smp", "setting", "quantity", "measured", "+/-", "simulated",
                           "+/-", "z", "rel", "pass");
  for (const auto& o : c.observables)
    std::cout << fmt::format(
        "{:<16} {:<4} {:<26} {:<15} {:>10.4g} {:>9.2g} {:>10.4g} {:>9.2g} {:>+7.2f} {:>+7.1f}% "
        "{} [{}]\n",
        o.measured.rig, o.measured.sample, o.measured.setting_text(), o.measured.quantity,
        o.measured.value, o.measured.std, o.simulated.mean, o.simulated.std, o.z, 100 * o.rel_error,
        o.pass ? "yes" : "NO ", o.measured.unit);
  std::cout << fmt::format("chi2 = {:.2f}, dof = {}, chi2/dof = {:.2f}\n", c.chi2, c.dof,
                           c.chi2_per_dof);
}

void check_outputs(const CalArgs& a) {
  if (!a.json.empty() && a.json != "-") check_writable(a.json, "--json");
  if (!a.report.empty()) {
    std::error_code ec;
    if (std::filesystem::exists(a.report, ec) && !std::filesystem::is_directory(a.report, ec))
      throw InputError(a.report, "--report", "exists and is not a folder");
    check_writable(std::filesystem::path(a.report) / "index.html", "--report");
  }
}

// Observables that are one measurement (a discharge's mass flow and pocket mass, say) would be
// counted twice in chi-squared: said on stderr, not refused (a lab may have measured both).
void warn_redundant(const std::vector<Measurement>& ms, const std::string& file) {
  for (const std::string& w : redundancy_warnings(ms, file))
    std::cerr << "clumpkit: warning: " << w << "\n";
}

Command setup_compare(CLI::App& parent) {
  auto a = std::make_shared<CalArgs>();
  CLI::App* c = parent.add_subcommand(
      "compare",
      "Run every rig and setting the measurements need and compare: measured and "
      "simulated mean +/- std, z, relative error, pass (|z| <= 2), chi2/dof");
  c->add_option("--model", a->models,
                "Model file or bundled name; repeat for a chain of model "
                "versions (the report shows chi2/dof per version)")
      ->required();
  c->add_option("--measurements", a->measurements,
                "Measurement CSV (rig,sample,setting,quantity,"
                "value,std,n,unit)")
      ->required();
  c->add_option("--report", a->report, "Write a self-contained HTML report into this folder");
  common_options(c, *a);
  return {c, [a] {
            rigs::check_engine(a->engine, a->np);
            const auto ms = load_measurements(a->measurements);  // validated before any run
            warn_redundant(ms, a->measurements);
            std::vector<ParticleModel> models;
            for (const auto& m : a->models) models.push_back(load_model(find_model(m), data_dir()));
            std::optional<OutputFolder> report_folder;  // gone again if no report is written
            if (!a->report.empty()) report_folder.emplace(a->report, "--report");
            check_outputs(*a);
            RigSimulator sim = make_sim(*a);
            ReportInput rep;
            json chain = json::array();
            // The versions of a chain share one pooled seed-to-seed spread (comparison.hpp).
            std::vector<std::map<std::string, SimulatedValue>> simulated;
            SpreadPool pool(ms);
            std::set<std::string> pooled_models;
            for (const auto& m : models) {
              simulated.push_back(simulate_measurements(sim, m, ms, a->scale, a->repeats, a->seed));
              if (pooled_models.insert(model_fingerprint(m)).second) pool.add(simulated.back());
            }
            for (size_t i = 0; i < models.size(); ++i) {
              const ParticleModel& m = models[i];
              const Comparison cmp = compare(ms, pool.pooled(simulated[i]));
              print_comparison(m.name, cmp);
              rep.chain.emplace_back(m.name, cmp);
              json j = comparison_json(cmp);
              j["model"] = m.name;
              chain.push_back(j);
            }
            std::cout << fmt::format("{} rig runs simulated, {} served from the cache ({})\n",
                                     sim.runs(), sim.cache_hits(), a->cache);
            if (!a->json.empty()) {
              json out = chain.back();
              out["scale"] = a->scale;
              out["repeats"] = a->repeats;
              out["engine"] = a->engine;
              out["mpi_ranks"] = mpi_ranks(*a);
              if (chain.size() > 1) out["chain"] = chain;
              write_json(out, a->json);
            }
            if (!a->report.empty()) {
              rep.pictures = sim.pictures();
              write_report(rep, a->report);
              std::cout << "report: " << (std::filesystem::path(a->report) / "index.html").string()
                        << "\n";
            }
            return 0;
          }};
}

Command setup_diagnose(CLI::App& parent) {
  auto a = std::make_shared<CalArgs>();
  CLI::App* c = parent.add_subcommand(
      "diagnose",
      "Find the physical effect the model lacks: fit each candidate effect (SPEC §8) to the "
      "measurements with real rig runs, rank by BIC, say which observables drive it, which "
      "effects are indistinguishable and which measurement would separate them");
  c->add_option("--model", a->models, "Baseline model file or bundled name")
      ->required()
      ->expected(1);
  c->add_option("--measurements", a->measurements, "Measurement CSV")->required();
  c->add_option("--effects", a->effects, "Comma-separated effect ids to try (default: all)");
  c->add_option("--report", a->report, "Write a self-contained HTML report into this folder");
  c->add_flag("--apply", a->apply, "Write the model with the winning effect at its fitted value");
  c->add_option("-o,--output", a->output, "With --apply: the new model file (.toml)");
  c->add_option("--suggest", a->suggest,
                "When to simulate unmeasured settings for the next-measurement suggestion: "
                "ambiguous (a verdict with an indistinguishable effect or a confidence below "
                "0.9), always, or never")
      ->capture_default_str()
      ->check(CLI::IsMember({"ambiguous", "always", "never"}));
  c->add_flag("--no-suggest", a->no_suggest, "The same as --suggest never");
  c->add_flag("--no-pairs", a->no_pairs,
              "Never fit two effects at once (by default a pair is tried where no single effect "
              "explains the data)");
  c->add_option("--screen-repeats", a->screen_repeats,
                "Repeats of the first phase's probes and discrete levels (a screen; the "
                "leaders get --repeats when refined). Set it to --repeats for a full first "
                "phase")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  c->add_option("--end-runs", a->end_runs,
                "Runs (with --repeats) at the far end of the leading candidate's 95 % "
                "interval where it reaches past the strengths simulated for it, at most this "
                "many, after the ranking (they can only widen the interval); 0: none (such an "
                "interval is then only marked *)")
      ->capture_default_str()
      ->check(CLI::Range(0, 10));
  common_options(c, *a);
  return {
      c, [a] {
        rigs::check_engine(a->engine, a->np);
        const auto ms = load_measurements(a->measurements);
        warn_redundant(ms, a->measurements);
        if (ms.size() < 3)
          throw InputError(a->measurements, "",
                           fmt::format("{} observable(s) are too few to tell effects apart "
                                       "(need at least 3)",
                                       ms.size()));
        const ParticleModel base = load_model(find_model(a->models.front()), data_dir());
        if (a->apply && a->output.empty())
          throw InputError("", "--output", "--apply needs -o NEW_MODEL.toml");
        if (!a->output.empty()) check_writable(a->output, "--output");
        std::optional<OutputFolder> report_folder;  // gone again if no report is written
        if (!a->report.empty()) report_folder.emplace(a->report, "--report");
        check_outputs(*a);
        DiagnoseOptions o;
        o.scale = a->scale;
        o.repeats = a->repeats;
        o.screen_repeats = a->screen_repeats;
        o.end_runs = a->end_runs;
        o.seed = a->seed;
        o.suggest = !a->no_suggest && a->suggest != "never";
        o.suggest_always = a->suggest == "always";
        o.pairs = !a->no_pairs;
        o.engine = a->engine;
        std::string list = a->effects;
        for (size_t p; (p = list.find(',')) != std::string::npos; list.erase(0, p + 1))
          if (p > 0) o.effects.push_back(list.substr(0, p));
        if (!list.empty()) o.effects.push_back(list);
        effect_candidates(base, o.effects, nullptr, "--effects");  // names checked up front
        if (!a->quiet)
          o.progress = [](const std::string& s) { std::cerr << "diagnose: " << s << "\n"; };
        RigSimulator sim = make_sim(*a);
        const Diagnosis d = diagnose(base, ms, sim, o);
        std::cout << fmt::format(
            "{:<18} {:<38} {:>14} {:>10} {:>22} {:>9} {:>9} {:>9} {:>7} {:<13} {}\n", "effect",
            "parameter", "fitted", "+/-", "95 % interval", "chi2", "dchi2", "BIC", "weight",
            "plausible", "chi2 from");
        std::cout << fmt::format("{:<18} {:<38} {:>14} {:>10} {:>22} {:>9.2f} {:>9} {:>9.2f}\n",
                                 "(baseline)", base.name, "", "", "", d.baseline.chi2, "",
                                 d.baseline_bic);
        for (const auto& r : d.candidates)
          std::cout << fmt::format(
              "{:<18} {:<38} {:>14} {:>10.3g} {:>22} {:>9.2f} {:>+9.2f} {:>9.2f} {:>7.3f} {:<13} "
              "{}\n",
              r.candidate.effect, parameter_text(r), r.candidate.format(r.fitted), r.fitted_std,
              interval_text(r), r.comparison.chi2, r.delta_chi2, r.bic, r.weight,
              r.plausible  ? "yes"
              : r.at_limit ? "no (at limit)"
                           : "no (at bound)",
              chi2_source_text(r));
        if (std::any_of(d.candidates.begin(), d.candidates.end(),
                        [](const CandidateResult& r) { return r.interval_past_runs(); }))
          std::cout << kIntervalPastRunsNote << "\n";
        for (const auto& r : d.candidates)
          if (!r.limit.empty())
            std::cout << "limit: " << r.candidate.effect << ": " << r.limit << "\n";
        for (const auto& s : d.skipped) std::cout << "not tried: " << s << "\n";
        std::cout << d.summary();
        std::cout << fmt::format("{} rig runs simulated, {} served from the cache\n", sim.runs(),
                                 sim.cache_hits());
        json cands = json::array();
        // An effect's fit: the candidate's (or a pair's second effect's) parameter and values.
        auto fit_json = [](const EffectCandidate& e, double value, double sd, double lo,
                           double hi) {
          return json{{"effect", e.effect},
                      {"parameter", e.parameter},
                      {"unit", e.unit},
                      {"fitted",
                       {{"value", value},
                        {"std", sd},
                        {"interval_95", {lo, hi}},
                        {"partners", e.partners ? json(e.partners(value)) : json(nullptr)}}},
                      {"range", {e.lo, e.hi}}};
        };
        for (const auto& r : d.candidates) {
          json entry = fit_json(r.candidate, r.fitted, r.fitted_std, r.fitted_lo, r.fitted_hi);
          entry.update({{"chi2", r.comparison.chi2},
                        {"chi2_per_dof", r.comparison.chi2_per_dof},
                        {"delta_chi2", r.delta_chi2},
                        {"bic", r.bic},
                        {"weight", r.weight},
                        {"plausible", r.plausible},
                        {"at_bound", r.at_bound},
                        {"limit", r.limit},
                        {"at_limit", r.at_limit},
                        {"chi2_source", r.chi2_source},
                        {"chi2_at", r.chi2_at},
                        {"runs_span", r.candidate.discrete || r.with ? json(nullptr)
                                                                     : json{r.runs_lo, r.runs_hi}},
                        {"interval_past_runs", r.interval_past_runs()},
                        {"end_runs", r.end_runs},
                        {"with", r.with ? fit_json(r.with->candidate, r.with->fitted, r.with->std,
                                                   r.with->lo, r.with->hi)
                                        : json(nullptr)}});
          cands.push_back(entry);
        }
        json sugg = json::array();
        for (const auto& s : d.suggestions)
          sugg.push_back({{"rig", s.rig},
                          {"sample", s.sample},
                          {"setting", s.setting},
                          {"quantity", s.quantity},
                          {"separation_sigma", s.separation},
                          {"between", s.between}});
        json out = {{"baseline", comparison_json(d.baseline)},
                    {"baseline_bic", d.baseline_bic},
                    {"baseline_p", d.baseline_p},
                    {"candidates", cands},
                    {"verdict",
                     {{"effect", d.consistent ? json(nullptr) : json(d.verdict)},
                      {"consistent", d.consistent},
                      {"confidence", d.confidence}}},
                    {"drivers", d.drivers},
                    {"indistinguishable", d.indistinguishable},
                    {"suggestions", sugg},
                    {"suggestion_note", d.suggestion_note},
                    {"screen_only", d.screen_only},
                    {"skipped", d.skipped},
                    {"simulations", d.simulations},
                    {"engine", a->engine},
                    {"mpi_ranks", mpi_ranks(*a)},
                    {"summary", d.summary()}};
        ReportInput rep;
        rep.chain.emplace_back(base.name, d.baseline);
        if (a->apply) {
          if (d.consistent) {
            std::cout << "--apply: nothing to add, the model is consistent with the data\n";
          } else {
            const CandidateResult& top = d.candidates.front();
            ParticleModel next = top.candidate.apply(base, top.fitted);
            next.name = base.name + "+" + top.candidate.effect;
            std::string added =
                fmt::format("{} = {}", top.candidate.parameter, top.candidate.format(top.fitted));
            if (top.with)
              added += fmt::format(" and {} = {}", top.with->candidate.parameter,
                                   top.with->candidate.format(top.with->fitted));
            write_file_atomic(a->output,
                              format_model(next, a->output,
                                           fmt::format("{} with {} added by clumpkit diagnose",
                                                       base.name, added)));
            out["applied"] = {{"effect", top.candidate.effect}, {"model", a->output}};
            rep.chain.emplace_back(next.name, top.comparison);
            std::cout << "wrote " << a->output << " (" << next.name << ")\n";
          }
        }
        if (!a->json.empty()) write_json(out, a->json);
        if (!a->report.empty()) {
          rep.title = "clumpkit diagnose: " + base.name;
          rep.diagnosis = &d;
          rep.pictures = sim.pictures();
          write_report(rep, a->report);
          std::cout << "report: " << (std::filesystem::path(a->report) / "index.html").string()
                    << "\n";
        }
        return 0;
      }};
}

Command setup_synth(CLI::App& parent) {
  auto a = std::make_shared<CalArgs>();
  std::string templ;
  CLI::App* c = parent.add_subcommand(
      "synth",
      "Synthetic measurements from a truth model with realistic noise, to check the "
      "compare/diagnose loop end to end");
  c->add_option("--model", a->models, "Truth model file or bundled name")->required()->expected(1);
  c->add_option("--measurements-template", a->measurements,
                "CSV whose rows (rig, sample, setting, quantity, n, unit) are synthesised")
      ->required();
  c->add_option("--noise", a->noise, "Relative standard deviation of one lab repeat")
      ->check(CLI::Range(1e-6, 1.0))
      ->capture_default_str();
  c->add_option("-o,--output", a->output, "Output CSV")->required();
  // The truth's mean is estimated from its repeats, and synth states an std that covers that
  // estimate's error: from 2 repeats (the other commands' default) the stated std of a mini
  // heap angle was 4.0 deg for a lab noise of 0.9 deg, and a hidden effect drowned in it.
  a->repeats = 4;
  common_options(c, *a);
  return {c, [a] {
            rigs::check_engine(a->engine, a->np);
            auto ms = load_measurements(a->measurements);
            warn_redundant(ms, a->measurements);
            const ParticleModel truth = load_model(find_model(a->models.front()), data_dir());
            check_writable(a->output, "--output");
            RigSimulator sim = make_sim(*a);
            // The truth is simulated with seeds the diagnosis will not use by default.
            const std::uint64_t seed = a->seed + 1000003;
            // The truth's seed-to-seed spread pooled over each rig quantity's settings (the angle
            // on three plates): from a few repeats alone it is often several times too small.
            SpreadPool pool(ms);
            auto s = simulate_measurements(sim, truth, ms, a->scale, a->repeats, seed);
            pool.add(s);
            s = pool.pooled(std::move(s));
            std::mt19937_64 rng(a->seed);
            for (auto& m : ms) {
              const SimulatedValue& t = s.at(m.key());
              const double v = t.mean;
              double lab = a->noise * std::abs(v);
              if (lab <= 0) lab = a->noise;
              std::normal_distribution<double> g(0.0, lab / std::sqrt(static_cast<double>(m.n)));
              m.value = v + g(rng);
              if (m.value < 0 && m.unit != "deg") m.value = 0.0;
              // The truth's mean is itself an estimate from a few seeds: its standard error is
              // folded into the stated std, so that std / sqrt(n) covers both.
              const double se_truth = t.n > 1 ? t.std / std::sqrt(static_cast<double>(t.n)) : 0.0;
              m.std = std::sqrt(lab * lab + m.n * se_truth * se_truth);
            }
            write_file_atomic(
                a->output,
                fmt::format("# synthetic: truth model {}, noise {} relative, seed {}, "
                            "scale {}{}\n",
                            truth.name, a->noise, a->seed, a->scale,
                            a->engine == "clumpkit"
                                ? ""
                                : fmt::format(", engine {} ({} MPI rank(s))", a->engine, a->np)) +
                    format_measurements(ms));
            std::cout << fmt::format("wrote {} measurements to {}\n", ms.size(), a->output);
            return 0;
          }};
}

const Registration reg_compare(60, setup_compare);
const Registration reg_diagnose(61, setup_diagnose);
const Registration reg_synth(62, setup_synth);

}  // namespace
}  // namespace clumpkit::cli
#endif
