#include "clumpkit/calibrate/diagnosis.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <iostream>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "clumpkit/core/error.hpp"
#include "fake_simulator.hpp"

using namespace clumpkit;
using namespace clumpkit::calibrate;

namespace {

ParticleModel base_model() {
  ParticleModel m =
      load_model(CLUMPKIT_SOURCE_DIR "/shapes/models/paper_A12.toml", CLUMPKIT_SOURCE_DIR);
  return m;
}

// The stand-in's measurement template: three cups, two plates, three wheel speeds.
const char* const kTemplate =
    "rig,sample,setting,quantity,value,std,n,unit\n"
    "bulk_density,A,wall=organic_glass,bulk_density,1,1,3,kg/m^3\n"
    "bulk_density,A,wall=galvanized_steel,bulk_density,1,1,3,kg/m^3\n"
    "bulk_density,A,wall=abs_plastic,bulk_density,1,1,3,kg/m^3\n"
    "angle_of_repose,A,plate=galvanized_steel,angle,1,1,3,deg\n"
    "angle_of_repose,A,plate=abs_plastic,angle,1,1,3,deg\n"
    "discharge,A,rpm=10,pocket_mass,1,1,3,kg\n"
    "discharge,A,rpm=15,pocket_mass,1,1,3,kg\n"
    "discharge,A,rpm=30,pocket_mass,1,1,3,kg\n";

// Measurements from a truth model: the template's rows, values = simulation with a seed the
// diagnosis never uses, plus lab noise of relative size `rel`.
std::vector<Measurement> synthesize(Simulator& sim, const ParticleModel& truth, double rel,
                                    std::uint64_t seed, const std::string& csv = kTemplate) {
  auto ms = parse_measurements(csv, "template.csv");
  auto sims = simulate_measurements(sim, truth, ms, "mini", 3, seed);
  std::mt19937_64 rng(seed);
  for (auto& m : ms) {
    const double v = sims.at(m.key()).mean;
    m.std = rel * std::abs(v);
    std::normal_distribution<double> g(0.0, m.std / std::sqrt(m.n));
    m.value = v + g(rng);
  }
  return ms;
}

struct Hidden {
  std::string effect, key, value;
  double truth;
};

// The paper's A12 model as a baseline with rolling friction `base_mu_r` ("off" or a value) and
// a truth that differs from it in rolling friction only (`truth_mu_r`).
std::pair<ParticleModel, ParticleModel> rolling_friction_baseline_and_truth(
    const std::string& base_mu_r, const std::string& truth_mu_r) {
  ParticleModel base = base_model();
  set_model_effect(base, "effects.rolling_friction", base_mu_r, "test");
  ParticleModel truth = base;
  set_model_effect(truth, "effects.rolling_friction", truth_mu_r, "test");
  return {base, truth};
}

// The paper's A12 model without cohesion as a baseline, and the same with `truth` J/m^3 of it.
std::pair<ParticleModel, ParticleModel> cohesion_baseline_and_truth(const std::string& truth) {
  ParticleModel base = base_model();
  set_model_effect(base, "effects.cohesion", "off", "test");
  ParticleModel t = base;
  set_model_effect(t, "effects.cohesion", truth + " J/m^3", "test");
  return {base, t};
}

// The heaps on three plates measured as `clumpkit synth` makes them: the truth's mean over 4
// seeds plus 3 % lab noise, the stated std widened by the truth's own standard error.
std::vector<Measurement> heaps_as_synth_makes_them(Simulator& sim, const ParticleModel& truth,
                                                   std::uint64_t seed) {
  auto ms = parse_measurements(
      "rig,sample,setting,quantity,value,std,n,unit\n"
      "angle_of_repose,A,plate=galvanized_steel,angle,1,1,3,deg\n"
      "angle_of_repose,A,plate=abs_plastic,angle,1,1,3,deg\n"
      "angle_of_repose,A,plate=organic_glass,angle,1,1,3,deg\n",
      "template.csv");
  const auto sims = simulate_measurements(sim, truth, ms, "mini", 4, seed);
  std::mt19937_64 rng(seed);
  for (auto& m : ms) {
    const SimulatedValue& v = sims.at(m.key());
    const double lab = 0.03 * v.mean;
    m.value = v.mean + std::normal_distribution<double>(0.0, lab / std::sqrt(m.n))(rng);
    m.std = std::sqrt(lab * lab + m.n * v.std * v.std / v.n);
  }
  return ms;
}

// The stand-in with its cohesion law reshaped: `shape` maps the model's cohesion (J/m^3) to the
// stand-in's linear one; runs above `limit` fail (the tube lifts the heap). 1 % seed noise per
// run and no common random numbers, as the rigs' chaotic runs.
struct ShapedCohesion final : Simulator {
  explicit ShapedCohesion(std::function<double(double)> f) : shape(std::move(f)) {
    inner.noise_rel = 0.01;
    inner.common_random_numbers = false;
  }
  std::function<double(double)> shape;
  double limit = 4e4;
  double lowest_failure = std::numeric_limits<double>::infinity();  ///< of the runs made
  fake::FakeSimulator inner;
  SimValues simulate(const ParticleModel& m, const SimRequest& r, int repeats,
                     std::uint64_t seed) override {
    ParticleModel s = m;
    const double c = m.effects.cohesion.value_or(0.0);
    if (c > limit) {
      lowest_failure = std::min(lowest_failure, c);
      throw NumericalError("heap angle: the heap is only 5 mm high: no cone");
    }
    if (c > 0) s.effects.cohesion = shape(c);
    ++runs_;
    return inner.simulate(s, r, repeats, seed);
  }
};

}  // namespace

// Seeded end-to-end test of the logic on the analytic stand-in: for each hidden effect, the
// diagnosis from a baseline without it ranks it first, and the fitted strength agrees with the
// truth within its stated uncertainty (2 sigma).
TEST(Diagnosis, FindsEachHiddenEffect) {
  const Hidden cases[] = {
      {"rolling_friction", "effects.rolling_friction", "0.12", 0.12},
      {"cohesion", "effects.cohesion", "9000 J/m^3", 9000.0},
      {"wall_friction", "effects.wall_friction", "0.45", 0.45},
      {"shape_resolution", "effects.shape_resolution", "4", 4.0},
      {"size_distribution", "effects.size_distribution", "0.12", 0.12},
  };
  double sum_chi2_per_dof = 0.0;
  std::uint64_t seed = 4242;
  for (const Hidden& h : cases) {
    ++seed;  // fresh lab noise for each case
    fake::FakeSimulator sim;
    ParticleModel base = base_model();
    set_model_effect(base, h.key, "off", "test");
    ParticleModel truth = base;
    set_model_effect(truth, h.key, h.value, "test");
    const auto ms = synthesize(sim, truth, 0.02, seed);
    DiagnoseOptions o;
    o.suggest_always = true;  // the suggestion's machinery on every case
    o.suggest_max = 2;
    const Diagnosis d = diagnose(base, ms, sim, o);
    ASSERT_FALSE(d.consistent) << h.effect << "\n" << d.summary();
    EXPECT_EQ(d.verdict, h.effect) << d.summary();
    const CandidateResult& top = d.candidates.front();
    if (top.candidate.discrete) {
      EXPECT_EQ(top.fitted, h.truth);
    } else {
      EXPECT_LE(std::abs(top.fitted - h.truth), 2.0 * top.fitted_std + 1e-12)
          << h.effect << " fitted " << top.fitted << " +/- " << top.fitted_std;
    }
    // After the effect is added the misfit is within noise: its chi2 is a plausible draw
    // (p >= 0.01) for every case, and chi2/dof <= 1.5 on average over the cases.
    EXPECT_GE(chi2_survival(top.comparison.chi2, top.comparison.dof), 0.01) << d.summary();
    sum_chi2_per_dof += top.comparison.chi2_per_dof;
    EXPECT_GE(d.confidence, 0.5);
    EXPECT_FALSE(d.suggestions.empty());
    // The verdict rests on runs with every repeat, not on the one-repeat screen (a discrete
    // level that leads is simulated again).
    for (const auto& ob : top.comparison.observables) EXPECT_EQ(ob.simulated.n, 2) << h.effect;
  }
  EXPECT_LE(sum_chi2_per_dof / std::size(cases), 1.5);
}

// Seeded property: when one rig run scatters as much as a small heap does (8 % of the angle, ~2.5
// deg), each variant's noise is its own (no common random numbers) and the diagnosis has two
// repeats per variant, the stated uncertainty of the fitted
// strength still covers the truth (2 sigma) in most trials. Before the spread was pooled over the
// variants and the surrogate smoothed the noisy points, a two-repeat spread could be several
// times too small and the fitted value many stated sigmas away; a noisy parabola that turned over
// between its points trapped the fit at its extremum.
TEST(Diagnosis, StatedUncertaintyCoversTheTruthWhenRunsAreNoisy) {
  const int trials = 40;
  int covered = 0, covered95 = 0, first = 0, covered1 = 0;
  for (int t = 0; t < trials; ++t) {
    fake::FakeSimulator sim;
    sim.noise_rel = 0.08;
    sim.common_random_numbers = false;
    const auto [base, truth] = rolling_friction_baseline_and_truth("0.05", "0.2");
    const auto ms = heaps_as_synth_makes_them(sim, truth, 9000 + 17 * t);
    DiagnoseOptions o;
    o.effects = {"rolling_friction", "wall_friction"};
    o.suggest = false;
    o.seed = 1 + 1000 * t;  // the diagnosis's own seeds differ between trials too
    const Diagnosis d = diagnose(base, ms, sim, o);
    ASSERT_FALSE(d.candidates.empty());
    const CandidateResult& top = d.candidates.front();
    first += top.candidate.effect == "rolling_friction";
    covered += top.candidate.effect == "rolling_friction" &&
               std::abs(top.fitted - 0.2) <= 2.0 * top.fitted_std;
    covered1 +=
        top.candidate.effect == "rolling_friction" && std::abs(top.fitted - 0.2) <= top.fitted_std;
    covered95 +=
        top.candidate.effect == "rolling_friction" && top.fitted_lo <= 0.2 && 0.2 <= top.fitted_hi;
  }
  EXPECT_EQ(first, trials);
  std::cout << "rolling friction ranked first in " << first << " of " << trials
            << " trials, truth within 2 stated sigma in " << covered
            << ", within the 95 % interval in " << covered95 << ", within 1 stated sigma in "
            << covered1 << "\n";
  EXPECT_GE(covered95, 34) << covered95 << " of " << trials << " in the 95 % interval";
  // Nominal 2-sigma coverage is 95 % (38 of 40); measured 37 (38 before session 14's local
  // surrogate). With a two-repeat spread and an interpolating surrogate it was 19 of 40.
  EXPECT_GE(covered, 34) << covered << " of " << trials << " cover the truth";
  // Nominal 1-sigma coverage is 68 % (27 of 40, binomial spread ~3); measured 26 (session 43).
  // A stated sigma that is too small shows here first (issue 7: the fitted strength within its
  // stated uncertainty of the truth).
  EXPECT_GE(covered1, 22) << covered1 << " of " << trials << " within 1 stated sigma";
  // Nor inflated out of use: the surrogate's redraws (session 44) widen sigma where the curve is
  // uncertain, not everywhere (31 of 40 within 1 sigma with them, 26 without; nominal 27).
  EXPECT_LE(covered1, 36) << covered1 << " of " << trials << " within 1 stated sigma";
}

// Seeded property: where each variant's mean scatters about the smooth response by more than its
// repeats say (a scatter every repeat of one model shares, 3 times the seed-to-seed one), the
// surrogate weighs its points by the scatter they show (Surrogate::scatter_var), so the stated
// uncertainty still covers the truth. Weighed by the repeats' spread alone, nearby refinement
// means that differ by that scatter read as a steep local slope: the stated sigma was then
// several times too small (the truth within 2 stated sigma in 15 of 40 trials, within 1 in 6;
// with the scatter of each observable alone, not pooled over its family, 33 and 23).
TEST(Diagnosis, StatedUncertaintyCoversTheTruthWhenVariantsScatterMoreThanTheirRepeats) {
  const int trials = 40;
  int covered = 0, covered1 = 0;
  for (int t = 0; t < trials; ++t) {
    fake::FakeSimulator lab_sim;  // the lab: the truth's smooth response plus seed noise
    lab_sim.noise_rel = 0.02;
    lab_sim.common_random_numbers = false;
    fake::FakeSimulator sim = lab_sim;
    sim.variant_noise_rel = 0.06;
    sim.variant_seed = 31 + t;
    const auto [base, truth] = rolling_friction_baseline_and_truth("0.05", "0.2");
    const auto ms = heaps_as_synth_makes_them(lab_sim, truth, 7000 + 13 * t);
    DiagnoseOptions o;
    o.effects = {"rolling_friction"};
    o.suggest = false;
    o.seed = 1 + 1000 * t;
    const Diagnosis d = diagnose(base, ms, sim, o);
    ASSERT_FALSE(d.candidates.empty());
    const CandidateResult& top = d.candidates.front();
    ASSERT_EQ(top.candidate.effect, "rolling_friction");
    covered += std::abs(top.fitted - 0.2) <= 2.0 * top.fitted_std;
    covered1 += std::abs(top.fitted - 0.2) <= top.fitted_std;
  }
  std::cout << "truth within 2 stated sigma in " << covered << " of " << trials
            << ", within 1 stated sigma in " << covered1 << "\n";
  // Nominal: 38 and 27 of 40; measured 37 and 31.
  EXPECT_GE(covered, 34) << covered << " of " << trials << " cover the truth";
  EXPECT_GE(covered1, 22) << covered1 << " of " << trials << " within 1 stated sigma";
}

TEST(Diagnosis, NoFalseVerdictWhenNothingIsMissing) {
  for (std::uint64_t seed : {11u, 12u, 13u}) {
    fake::FakeSimulator sim;
    const ParticleModel base = base_model();
    const auto ms = synthesize(sim, base, 0.02, seed);
    DiagnoseOptions o;
    o.suggest = false;
    const Diagnosis d = diagnose(base, ms, sim, o);
    EXPECT_TRUE(d.consistent) << d.summary();
    EXPECT_TRUE(d.verdict.empty());
    // Consistent after the screen: no refinement or confirmation runs (the baseline, one probe
    // per continuous effect and one run per discrete level), the same verdict as with them.
    EXPECT_TRUE(d.screen_only) << d.summary();
    for (const CandidateResult& r : d.candidates)  // "run": fitted at the baseline's own run
      EXPECT_TRUE(r.chi2_source == "surrogate" || r.chi2_source == "screen" ||
                  r.chi2_source == "nearest_run" ||
                  (r.chi2_source == "run" && r.fitted == r.candidate.baseline))
          << r.candidate.effect << " " << r.chi2_source;
    DiagnoseOptions full = o;
    full.p_screen_only = 1.01;
    fake::FakeSimulator sim2;
    const Diagnosis d2 = diagnose(base, ms, sim2, full);
    EXPECT_FALSE(d2.screen_only);
    EXPECT_TRUE(d2.consistent) << d2.summary();
    EXPECT_LT(d.simulations, d2.simulations);
  }
}

// A candidate whose variant the rigs cannot measure (e.g. a heap that spreads flat) is ruled out
// with its reason; the diagnosis goes on with the others.
TEST(Diagnosis, ACandidateThatCannotBeSimulatedIsSkippedWithItsReason) {
  struct Failing final : Simulator {
    double base_wall = 0.0;
    fake::FakeSimulator inner;
    SimValues simulate(const ParticleModel& m, const SimRequest& r, int repeats,
                       std::uint64_t seed) override {
      // Any wall friction other than the baseline's cannot be measured.
      const auto wall = m.effects.wall_friction;
      if (wall && wall->count("galvanized_steel") && wall->at("galvanized_steel") != base_wall)
        throw NumericalError("heap angle: the heap is too flat to measure");
      ++runs_;
      return inner.simulate(m, r, repeats, seed);
    }
  } sim;
  ParticleModel base = base_model();
  set_model_effect(base, "effects.rolling_friction", "off", "test");
  sim.base_wall = base.effects.wall_friction->at("galvanized_steel");
  ParticleModel truth = base;
  set_model_effect(truth, "effects.rolling_friction", "0.12", "test");
  const auto ms = synthesize(sim.inner, truth, 0.02, 77);
  DiagnoseOptions o;
  o.suggest = false;
  o.effects = {"rolling_friction", "wall_friction", "cohesion"};
  const Diagnosis d = diagnose(base, ms, sim, o);
  EXPECT_EQ(d.verdict, "rolling_friction") << d.summary();
  for (const auto& c : d.candidates) EXPECT_NE(c.candidate.effect, "wall_friction");
  ASSERT_FALSE(d.skipped.empty());
  EXPECT_NE(d.skipped.front().find("wall_friction"), std::string::npos);
  EXPECT_NE(d.skipped.front().find("too flat"), std::string::npos);
}

// A hidden effect whose strength lies just below where the rigs stop measuring (strong
// cohesion: past some strength the lifting tube carries the heap off, "no cone to measure").
// The response is convex, so the secant from the probe overshoots into the failing region;
// the failed run must narrow the candidate's range, not drop it: the refinement bisects back
// toward the last measured value and the hidden effect is still found and fitted.
TEST(Diagnosis, AFailedRunNarrowsTheRangeInsteadOfDroppingTheCandidate) {
  struct Limited final : Simulator {
    double limit = 15000.0;  // J/m^3: runs above fail
    int failures = 0;
    fake::FakeSimulator inner;
    SimValues simulate(const ParticleModel& m, const SimRequest& r, int repeats,
                       std::uint64_t seed) override {
      const double c = m.effects.cohesion.value_or(0.0);
      if (c > limit) {
        ++failures;
        throw NumericalError("heap angle: the heap is only 5 mm high: no cone to measure");
      }
      ParticleModel convex = m;
      if (c > 0) convex.effects.cohesion = c * c / 1e4;
      ++runs_;
      return inner.simulate(convex, r, repeats, seed);
    }
  } sim;
  ParticleModel base = base_model();
  set_model_effect(base, "effects.cohesion", "off", "test");
  ParticleModel truth = base;
  set_model_effect(truth, "effects.cohesion", "12000 J/m^3", "test");
  const auto ms = synthesize(sim, truth, 0.02, 99);
  DiagnoseOptions o;
  o.suggest = false;
  o.effects = {"cohesion", "rolling_friction", "particle_friction"};
  const Diagnosis d = diagnose(base, ms, sim, o);
  std::cout << d.summary();
  EXPECT_GE(sim.failures, 1) << "the first refinement should overshoot into the failing region";
  ASSERT_EQ(d.verdict, "cohesion") << d.summary();
  const CandidateResult& top = d.candidates.front();
  EXPECT_NE(top.limit.find("could not measure"), std::string::npos) << top.limit;
  EXPECT_NE(top.limit.find("no cone"), std::string::npos) << top.limit;
  EXPECT_LT(top.fitted, sim.limit);
  EXPECT_LE(std::abs(top.fitted - 12000.0), 2.0 * top.fitted_std + 1e-9)
      << top.fitted << " +/- " << top.fitted_std;
  EXPECT_EQ(top.chi2_source, "run");
  for (const auto& s : d.skipped) EXPECT_EQ(s.find("cohesion"), std::string::npos) << s;
}

// A run that fails at the bound of a candidate's range (a tiny LIGGGHTS diagnosis, session 38:
// pill-wall friction refined at 0, where the heap spread flat, "no cone to measure"). The range
// must then end short of the bound as it does short of a failure inside it. Before, a failure at
// the bound did not narrow the range (it was the range's own end), the fit went back to it and
// the same failing run was made again. Here the data want no rolling friction at all and the
// rigs cannot measure below mu_r = 0.01: no value may fail twice, and rolling friction stays a
// candidate, fitted short of the failure.
TEST(Diagnosis, AFailureAtTheRangesBoundIsNotRunAgain) {
  struct Limited final : Simulator {
    std::vector<double> failed;
    fake::FakeSimulator inner;
    SimValues simulate(const ParticleModel& m, const SimRequest& r, int repeats,
                       std::uint64_t seed) override {
      const auto& rf = m.effects.rolling_friction;
      const double mur = rf && rf->count("pill") ? rf->at("pill") : 0.0;
      if (mur < 0.006) {
        failed.push_back(mur);
        throw NumericalError("heap angle: the heap is only 5 mm high: no cone to measure");
      }
      ++runs_;
      return inner.simulate(m, r, repeats, seed);
    }
  } sim;
  const ParticleModel base = base_model();  // Table 1: mu_r 0.05-0.12
  ParticleModel truth = base;
  set_model_effect(truth, "effects.rolling_friction", "0", "test");
  fake::FakeSimulator lab;  // the truth itself is measured
  const auto ms = synthesize(lab, truth, 0.02, 5);
  DiagnoseOptions o;
  o.suggest = false;
  o.effects = {"rolling_friction", "particle_friction"};
  const Diagnosis d = diagnose(base, ms, sim, o);
  EXPECT_GE(sim.failed.size(), 1u) << "a fit at the bound 0 should fail there";
  std::vector<double> values = sim.failed;
  std::sort(values.begin(), values.end());
  EXPECT_TRUE(std::adjacent_find(values.begin(), values.end()) == values.end())
      << "a failing value was run again; " << d.summary();
  bool found = false;
  for (const CandidateResult& r : d.candidates)
    if (r.candidate.effect == "rolling_friction") {
      found = true;
      EXPECT_NE(r.limit.find("no cone"), std::string::npos) << r.limit;
      EXPECT_GE(r.fitted, 0.006) << d.summary();
      EXPECT_TRUE(r.at_limit) << d.summary();
    }
  std::string fails, skipped;
  for (double v : sim.failed) fails += fmt::format(" {}", v);
  for (const auto& k : d.skipped) skipped += "\n  " + k;
  EXPECT_TRUE(found) << d.summary() << "failed at" << fails << "; skipped:" << skipped;
}

// Responses no parabola over the whole range follows: the packing may fall fast with the first
// bit of cohesion and then level off (the mini cup: 700 kg/m^3 without, 411 at 2e4 J/m^3), or
// barely move at the probe and then fast (the mini heaps: the secant from the 8000 J/m^3 probe
// aimed at 4.7e4 for a truth of 2e4, where the heap could not be measured). A least-squares
// parabola through the baseline, the probe and the refinements near the truth is biased where
// the fit is made, and a parabola that turns over fell back to a line far from every point.
// Measured over 16 lab-noise draws per shape (1 % seed noise per run, no common random
// numbers, 2 % lab noise), truth 2e4 J/m^3:
//   before (a global parabola or line, 2 refinements): the truth within 2 stated sigma in 0 and
//   0 of 16, the chi2 at the fit plausible (p >= 0.01, 7 dof) in 1 and 0 of 16, and 5 of the
//   accelerating draws gave the verdict to rolling friction pinned at its bound;
//   after (points far from the fit dropped where the parabola misses them, a monotone parabola
//   where the line misses them, up to 2 more steps for the leader): covered 11 (saturating)
//   and 14 (accelerating) of 16, plausible 16 and 16, cohesion the verdict in all.
// Where the response has levelled off the likelihood is skewed and the symmetric sigma short
// on one side, so the coverage stays below the nominal 95 %; the reported 95 % interval (Delta
// chi2 = 4 on the surrogate, asymmetric) covered the truth in 13 and 13 of 16 when this test was
// written. Measured again on session 46's code (the surrogate's own noise in the uncertainty, its
// points weighed by their scatter): 2 sigma 14 and 16, the 95 % interval 15 and 15 of 16; with the
// end runs of session 47 (AnIntervalPastTheRunsGetsARunAtItsEnd) 15 and 16, 15 and 15.
TEST(Diagnosis, ANonParabolicResponseIsFittedWhereTheFitIs) {
  const std::pair<const char*, std::function<double(double)>> shapes[] = {
      {"saturating", [](double c) { return 7.5e4 * (1.0 - std::exp(-c / 6e3)); }},
      {"accelerating", [](double c) { return 1e4 * std::expm1(c / 1e4); }},
  };
  for (const auto& [name, shape] : shapes) {
    int covered = 0, covered95 = 0, plausible = 0;
    const int trials = 16;
    for (int t = 0; t < trials; ++t) {
      ShapedCohesion sim(shape);
      const auto [base, truth] = cohesion_baseline_and_truth("20000");
      const auto ms = synthesize(sim, truth, 0.02, 500 + t);
      DiagnoseOptions o;
      o.suggest = false;
      o.effects = {"cohesion", "rolling_friction", "particle_friction"};
      o.seed = 1 + 100 * t;
      const Diagnosis d = diagnose(base, ms, sim, o);
      EXPECT_EQ(d.verdict, "cohesion") << name << "\n" << d.summary();
      if (d.verdict != "cohesion") continue;
      const CandidateResult& top = d.candidates.front();
      const bool cov = std::abs(top.fitted - 20000.0) <= 2.0 * top.fitted_std;
      const bool cov95 = top.fitted_lo <= 20000.0 && 20000.0 <= top.fitted_hi;
      EXPECT_LE(top.fitted_lo, top.fitted);
      EXPECT_GE(top.fitted_hi, top.fitted);
      const bool ok = chi2_survival(top.comparison.chi2, top.comparison.dof) >= 0.01;
      std::cout << name << " " << t << ": cohesion " << top.fitted << " +/- " << top.fitted_std
                << " [" << top.fitted_lo << ", " << top.fitted_hi << "] (" << top.chi2_source
                << "), chi2 " << top.comparison.chi2 << " on " << top.comparison.dof << " dof\n";
      covered += cov;
      covered95 += cov95;
      plausible += ok;
    }
    std::cout << name << ": truth within 2 stated sigma in " << covered << ", within the 95 % "
              << "interval in " << covered95 << " of " << trials << "\n";
    EXPECT_GE(covered, 9) << name;
    // Measured: 15 and 15 of 16 (session 46's code and since; 13 and 13 when written).
    EXPECT_GE(covered95, 12) << name;
    EXPECT_GE(plausible, trials - 1) << name;
  }
}

namespace {

// Pill-pill friction that saturates (the stand-in sees 1.5 (1 - exp(-mu / 0.15))): flat above
// Table 1's 0.47, steep below. `probe_error` is added to the galvanized plate's angles of the
// one-repeat runs between 0.6 and 0.8 (where the probe lands): a noisy probe.
struct SaturatingFriction final : Simulator {
  fake::FakeSimulator inner;
  double probe_error = 0.0;
  int below = 0;  // runs below the baseline
  SimValues simulate(const ParticleModel& m, const SimRequest& r, int repeats,
                     std::uint64_t seed) override {
    ParticleModel s = m;
    const double mu = m.effects.particle_friction.value_or(0.0);
    below += mu < 0.46;
    s.effects.particle_friction = 1.5 * (1.0 - std::exp(-mu / 0.15));
    ++runs_;
    SimValues v = inner.simulate(s, r, repeats, seed);
    if (probe_error != 0.0 && repeats == 1 && mu > 0.6 && mu < 0.8 && r.settings.count("plate") &&
        r.settings.at("plate") == "galvanized_steel")
      for (auto& [q, val] : v)
        if (q.rfind("angle", 0) == 0) val.mean += probe_error;
    return v;
  }
};

// Table 1's 0.466 as the baseline, 0.2 hidden; the diagnosis over three candidates, its
// progress lines in `log`. `sim.below` counts the diagnosis's runs below the baseline.
Diagnosis diagnose_lower_friction(SaturatingFriction& sim, std::uint64_t seed, std::string& log) {
  sim.inner.noise_rel = 0.01;
  ParticleModel base = base_model();
  set_model_effect(base, "effects.particle_friction", "0.466", "test");
  ParticleModel truth = base;
  set_model_effect(truth, "effects.particle_friction", "0.2", "test");
  const auto ms = synthesize(sim, truth, 0.02, seed);
  sim.below = 0;
  DiagnoseOptions o;
  o.suggest = false;
  o.effects = {"particle_friction", "wall_friction", "restitution"};
  o.seed = seed;
  o.progress = [&](const std::string& line) { log += line + "\n"; };
  return diagnose(base, ms, sim, o);
}

}  // namespace

// A hidden effect on the side of the baseline the candidate was not probed on, where the
// response differs: pill-pill friction probed upward from Table 1's 0.466 (to 0.716) where the
// heap has stopped feeling it, hidden at 0.2 where it feels it strongly (the mini heaps: 27-31
// deg at 0.466 and 0.8, 21-25 deg at 0.2). Extrapolated from the flat side the surrogate saw
// nothing: in the mini case of session 14 particle friction was not even refined (surrogate chi2
// 49 at mu_s 0.013, the baseline's 46) and the verdict went to another effect. A screening run at
// the mirrored probe gives the unprobed side a point. Without it this stand-in's verdict is
// restitution pinned at its bound (particle friction 0.36, chi2 54 from its surrogate).
TEST(Diagnosis, AnEffectOnTheUnprobedSideOfTheBaselineIsFound) {
  for (std::uint64_t seed : {31u, 32u, 33u}) {
    SaturatingFriction sim;
    std::string log;
    const Diagnosis d = diagnose_lower_friction(sim, seed, log);
    EXPECT_GE(sim.below, 1) << "the unprobed side was never simulated";
    ASSERT_EQ(d.verdict, "particle_friction") << d.summary();
    const CandidateResult& top = d.candidates.front();
    EXPECT_LE(std::abs(top.fitted - 0.2), 2.0 * top.fitted_std)
        << top.fitted << " +/- " << top.fitted_std;
    EXPECT_GE(chi2_survival(top.comparison.chi2, top.comparison.dof), 0.01) << d.summary();
  }
}

// The same effect, but the one-repeat probe's noise points the wrong way. With Table 1's pills at
// mini (session 24) pill-pill friction 0.2 was hidden; its probe at 0.716 moved one heap down by
// 2.9 deg (seed noise: above 0.47 the heaps barely feel it), so its line's fit lay between the
// baseline and the probe, not on the unprobed side, no run was made below the baseline and
// restitution took the verdict. Here the probe's run on the galvanized plate reads 0.4 deg low
// (the friction's whole effect on a heap is ~2.6 deg); the line through the baseline and the
// probe cannot explain the data and does not point past the probe, so the other side is
// screened all the same: particle friction found in all three draws, within 2 stated sigma.
// With the mirror only where the fit lies on the unprobed side (before session 24): seed 31
// was mirrored, seed 32 found it by refinement (0.236 +/- 0.011, 3.2 sigma off), seed 33 never
// ran below the baseline and the verdict was restitution. (With a 0.5 deg error the line points
// past the probe for seed 32, which is screened further on instead and fitted 2.7 sigma off.)
TEST(Diagnosis, AnUnexplainedCandidateIsScreenedOnTheOtherSideToo) {
  for (std::uint64_t seed : {31u, 32u, 33u}) {
    SaturatingFriction sim;
    sim.probe_error = -0.4;
    std::string log;
    const Diagnosis d = diagnose_lower_friction(sim, seed, log);
    EXPECT_GE(sim.below, 1) << "the unprobed side was never simulated\n" << log;
    ASSERT_EQ(d.verdict, "particle_friction") << d.summary() << log;
    const CandidateResult& top = d.candidates.front();
    EXPECT_LE(std::abs(top.fitted - 0.2), 2.0 * top.fitted_std)
        << top.fitted << " +/- " << top.fitted_std;
  }
}

// An effect whose response sets in past the probe. In the mini bench of session 15 a restitution
// of 0.7 (Table 1: 0.2-0.3) lowered the heaps by 5-7 deg; the probe at 0.5 had barely moved them,
// the line through the baseline and the probe could not reach the data, restitution was neither
// refined nor confirmed, and a lower rolling friction took the verdict with confidence 1.00.
// Here restitution's effect on the heaps sets in at 0.45 and grows as the square; a lower
// rolling friction and other candidates lower the heaps too. One screening run at twice the
// probe's step shows restitution's effect, and it is fitted at the truth (0.749 +/- 0.003 for
// 0.75, the verdict). Before, its surrogate stayed the line through 0.2 and 0.5, it was neither
// refined nor confirmed, and rolling friction pinned at 0 was the verdict with confidence 1.00.
TEST(Diagnosis, AnEffectThatSetsInPastTheProbeIsFound) {
  fake::Adjusted sim;
  sim.adjust = [](const ParticleModel& m, const SimRequest&, int, SimValues& v) {
    const double e = m.effects.restitution ? m.effects.restitution->at("pill") : 1.0;
    const double x = std::max(0.0, (e - 0.45) / 0.3);
    for (auto& [q, val] : v)
      if (q.rfind("angle", 0) == 0) val.mean -= 6.0 * x * x;
  };
  const ParticleModel base = base_model();  // Table 1: e 0.2-0.3
  ParticleModel truth = base;
  set_model_effect(truth, "effects.restitution", "0.75", "test");
  const auto ms = synthesize(sim, truth, 0.02, 31);
  DiagnoseOptions o;
  o.suggest = false;
  o.effects = {"restitution",      "rolling_friction", "particle_friction",
               "shape_resolution", "cohesion",         "wall_friction"};
  const Diagnosis d = diagnose(base, ms, sim, o);
  ASSERT_FALSE(d.consistent) << d.summary();
  const auto& named = d.indistinguishable;
  EXPECT_TRUE(d.verdict == "restitution" ||
              std::find(named.begin(), named.end(), "restitution") != named.end())
      << d.summary();
  for (const CandidateResult& r : d.candidates)
    if (r.candidate.effect == "restitution") {
      EXPECT_TRUE(r.plausible) << d.summary();
      EXPECT_LE(std::abs(r.fitted - 0.75), 2.0 * r.fitted_std) << d.summary();
    }
}

// A discrete candidate's level is chosen on runs with every repeat, not on the one-repeat screen.
// In the mini bench of session 15 (truth: the CDT rolling model, baseline the standard one) both
// other models lowered the heap, the EPSD level screened better, only it was confirmed, and the
// verdict named EPSD. Here the EPSD level's one screening run happens to match the data (its mean
// over every repeat is 1.5 deg short of the truth's shift) and the CDT level's screening run is
// 0.3 deg off (its mean matches): the verdict must be CDT. Before, it was EPSD.
TEST(Diagnosis, ADiscreteLevelIsChosenOnRunsWithEveryRepeat) {
  fake::Adjusted sim;
  sim.strip = [](ParticleModel& m) { m.effects.rolling_model.reset(); };
  sim.adjust = [](const ParticleModel& m, const SimRequest& r, int repeats, SimValues& v) {
    double shift = 0;  // deg on every heap angle
    if (m.effects.rolling_model == dem::RollingModel::kCdt) shift = repeats == 1 ? -2.7 : -3.0;
    if (m.effects.rolling_model == dem::RollingModel::kEpsd) shift = repeats == 1 ? -3.0 : -1.5;
    if (r.rig == "angle_of_repose")
      for (auto& [q, x] : v) x.mean += shift;
  };
  const ParticleModel base = base_model();  // the standard rolling model
  ParticleModel truth = base;
  set_model_effect(truth, "effects.rolling_model", "cdt", "test");
  const auto ms = synthesize(sim, truth, 0.02, 77);
  DiagnoseOptions o;
  o.suggest = false;
  o.effects = {"rolling_model"};
  const Diagnosis d = diagnose(base, ms, sim, o);
  ASSERT_FALSE(d.consistent) << d.summary();
  ASSERT_EQ(d.verdict, "rolling_model") << d.summary();
  const CandidateResult& top = d.candidates.front();
  EXPECT_EQ(top.fitted, static_cast<double>(static_cast<int>(dem::RollingModel::kCdt)))
      << d.summary();
  for (const auto& ob : top.comparison.observables) EXPECT_EQ(ob.simulated.n, 2);
}

// LIGGGHTS has no standard rolling model and runs it as CDT, so on LIGGGHTS a baseline with
// one of the two is not screened against the other (the same physics there, run twice): only
// EPSD is tried, and the skipped level is named with the reason. A hidden EPSD is still found.
TEST(Diagnosis, OnLiggghtsTheRollingModelIsNotScreenedAgainstItsTwin) {
  for (const auto base_law : {dem::RollingModel::kStandard, dem::RollingModel::kCdt}) {
    fake::Adjusted sim;
    std::set<int> simulated_laws;
    sim.strip = [](ParticleModel& m) { m.effects.rolling_model.reset(); };
    sim.adjust = [&](const ParticleModel& m, const SimRequest& r, int, SimValues& v) {
      const auto law = m.effects.rolling_model.value_or(dem::RollingModel::kStandard);
      simulated_laws.insert(static_cast<int>(law));
      if (law == dem::RollingModel::kEpsd && r.rig == "angle_of_repose")
        for (auto& [q, x] : v) x.mean -= 3.0;
    };
    ParticleModel base = base_model();
    set_model_effect(base, "effects.rolling_model", dem::to_string(base_law), "test");
    ParticleModel truth = base;
    set_model_effect(truth, "effects.rolling_model", "epsd", "test");
    const auto ms = synthesize(sim, truth, 0.02, 78);
    simulated_laws.clear();
    DiagnoseOptions o;
    o.suggest = false;
    o.effects = {"rolling_model"};
    o.engine = "liggghts";
    const Diagnosis d = diagnose(base, ms, sim, o);
    const auto twin = base_law == dem::RollingModel::kStandard ? dem::RollingModel::kCdt
                                                               : dem::RollingModel::kStandard;
    EXPECT_EQ(simulated_laws.count(static_cast<int>(twin)), 0u) << d.summary();
    EXPECT_TRUE(std::any_of(d.skipped.begin(), d.skipped.end(), [&](const std::string& s) {
      return s.find(std::string("rolling_model=") + dem::to_string(twin)) == 0 &&
             s.find("on LIGGGHTS") != std::string::npos;
    })) << d.summary();
    ASSERT_EQ(d.verdict, "rolling_model") << d.summary();
    EXPECT_EQ(d.candidates.front().fitted,
              static_cast<double>(static_cast<int>(dem::RollingModel::kEpsd)));
  }
}

TEST(Diagnosis, ChiSquareSurvivalMatchesKnownValues) {
  EXPECT_NEAR(chi2_survival(3.841, 1), 0.05, 1e-4);
  EXPECT_NEAR(chi2_survival(18.307, 10), 0.05, 1e-4);
  EXPECT_NEAR(chi2_survival(10.0, 10), 0.4405, 1e-4);
  EXPECT_NEAR(chi2_survival(0.0, 3), 1.0, 1e-12);
}

// Candidates the surrogate puts far behind the best real run are not simulated again at their
// fitted value: the verdict and the leader's fit are those of a diagnosis that confirms every
// candidate, every unconfirmed one is at least the margin behind, and fewer runs are made.
TEST(Diagnosis, SkippingHopelessConfirmationsChangesNoVerdict) {
  int skipped_total = 0;
  for (const Hidden& h : {Hidden{"rolling_friction", "effects.rolling_friction", "0.12", 0.12},
                          Hidden{"cohesion", "effects.cohesion", "9000 J/m^3", 9000.0}}) {
    ParticleModel base = base_model();
    set_model_effect(base, h.key, "off", "test");
    ParticleModel truth = base;
    set_model_effect(truth, h.key, h.value, "test");
    fake::FakeSimulator lab;
    const auto ms = synthesize(lab, truth, 0.02, 515);
    DiagnoseOptions o;
    o.suggest = false;
    fake::FakeSimulator sim_a, sim_b;
    const Diagnosis a = diagnose(base, ms, sim_a, o);
    o.confirm_margin = std::numeric_limits<double>::infinity();
    const Diagnosis b = diagnose(base, ms, sim_b, o);
    EXPECT_EQ(a.verdict, h.effect) << a.summary();
    EXPECT_EQ(b.verdict, a.verdict);
    ASSERT_FALSE(a.candidates.empty());
    EXPECT_EQ(a.candidates.front().fitted, b.candidates.front().fitted);
    EXPECT_NE(a.candidates.front().chi2_source, "surrogate");
    int skipped = 0;
    for (const auto& c : a.candidates) {
      if (c.chi2_source != "surrogate") continue;
      ++skipped;
      // The margin is on the fit's chi2; the comparison's differs by the variances only.
      EXPECT_GE(c.comparison.chi2, a.candidates.front().comparison.chi2 + 0.5 * 25.0)
          << c.candidate.effect;
      EXPECT_LT(c.weight, 1e-4);
    }
    for (const auto& c : b.candidates) EXPECT_NE(c.chi2_source, "surrogate");
    // b also confirms the screened discrete levels that a cannot need.
    EXPECT_GE(sim_b.runs() - sim_a.runs(), skipped * static_cast<long>(ms.size()));
    skipped_total += skipped;
  }
  EXPECT_GT(skipped_total, 0) << "the test needs a hopeless candidate to mean anything";
}

// The next measurement is a setting of the experiment (a cup or plate material, a wheel speed),
// never one of the simulation (scale, stiffness, implicit damping).
TEST(Diagnosis, SuggestsOnlyExperimentalSettings) {
  const auto [base, truth] = rolling_friction_baseline_and_truth("off", "0.12");
  fake::FakeSimulator sim;
  auto ms = synthesize(sim, truth, 0.02, 99);
  ms.resize(3);  // the three cups only: the plates and the wheel speeds are left to suggest
  DiagnoseOptions o;
  o.effects = {"rolling_friction", "cohesion"};
  o.suggest_max = 100;
  o.suggest_always = true;
  const Diagnosis d = diagnose(base, ms, sim, o);
  ASSERT_FALSE(d.suggestions.empty());
  std::set<std::string> settings;
  for (const auto& s : d.suggestions) {
    settings.insert(s.rig + " " + s.setting);
    EXPECT_EQ(s.setting.find("implicit_damping"), std::string::npos) << s.setting;
    EXPECT_EQ(s.setting.find("stiffness"), std::string::npos) << s.setting;
    EXPECT_EQ(s.setting.find("scale"), std::string::npos) << s.setting;
  }
  EXPECT_TRUE(settings.count("angle_of_repose plate=abs_plastic")) << d.summary();
  EXPECT_TRUE(settings.count("discharge rpm=15")) << d.summary();
}

// The suggestion's runs are made only where a measurement is needed: not when the model is
// consistent with the data, nor for a decisive verdict (each says why in the summary), but when
// two effects explain the data alike.
TEST(Diagnosis, AMeasurementIsSuggestedOnlyWhereOneIsNeeded) {
  const auto [base, truth] = rolling_friction_baseline_and_truth("off", "0.12");
  DiagnoseOptions o;
  o.effects = {"rolling_friction", "cohesion", "particle_friction"};
  // Heap angles alone, and the two effects that raise them alike.
  const std::string heaps =
      "rig,sample,setting,quantity,value,std,n,unit\n"
      "angle_of_repose,A,plate=galvanized_steel,angle,1,1,3,deg\n"
      "angle_of_repose,A,plate=abs_plastic,angle,1,1,3,deg\n"
      "angle_of_repose,A,plate=organic_glass,angle,1,1,3,deg\n";
  DiagnoseOptions two = o;
  two.effects = {"rolling_friction", "cohesion"};
  {
    // Decisive: the whole template separates rolling friction from cohesion.
    fake::FakeSimulator sim;
    const auto ms = synthesize(sim, truth, 0.02, 17);
    const Diagnosis d = diagnose(base, ms, sim, o);
    ASSERT_EQ(d.verdict, "rolling_friction") << d.summary();
    ASSERT_TRUE(d.indistinguishable.empty()) << d.summary();
    EXPECT_TRUE(d.suggestions.empty());
    EXPECT_NE(d.suggestion_note.find("decisive"), std::string::npos) << d.suggestion_note;
    EXPECT_NE(d.summary().find("next measurement: none needed"), std::string::npos);
    DiagnoseOptions always = o;
    always.suggest_always = true;
    fake::FakeSimulator sim2;
    const Diagnosis d2 = diagnose(base, ms, sim2, always);
    EXPECT_EQ(d2.verdict, d.verdict);
    EXPECT_FALSE(d2.suggestions.empty());
    EXPECT_GT(d2.simulations, d.simulations);
  }
  {
    // Consistent: nothing is hidden.
    fake::FakeSimulator sim;
    const auto ms = synthesize(sim, base, 0.02, 18);
    const Diagnosis d = diagnose(base, ms, sim, o);
    ASSERT_TRUE(d.consistent) << d.summary();
    EXPECT_TRUE(d.suggestions.empty());
    EXPECT_NE(d.suggestion_note.find("consistent"), std::string::npos) << d.suggestion_note;
  }
  {
    // Ambiguous: heap angles alone, which rolling friction and cohesion raise alike.
    fake::FakeSimulator sim;
    const auto ms = synthesize(sim, truth, 0.02, 19, heaps);
    const Diagnosis d = diagnose(base, ms, sim, two);
    ASSERT_FALSE(d.consistent) << d.summary();
    ASSERT_FALSE(d.indistinguishable.empty()) << d.summary();
    EXPECT_FALSE(d.suggestions.empty()) << d.summary();
    EXPECT_TRUE(d.suggestion_note.empty()) << d.suggestion_note;
  }
  {
    // A runner-up pinned at the top of its plausible range: heaps raised by a cohesion that
    // rolling friction matches only at its bound (0.5), 2.8 BIC units behind (weight 0.2). A
    // red flag, not an explanation: no measurement is simulated to rule it out.
    ParticleModel sticky = base;
    set_model_effect(sticky, "effects.cohesion", "1.66e4 J/m^3", "test");
    fake::FakeSimulator sim;
    const auto ms = synthesize(sim, sticky, 0.02, 21, heaps);
    const Diagnosis d = diagnose(base, ms, sim, two);
    ASSERT_EQ(d.verdict, "cohesion") << d.summary();
    ASSERT_EQ(d.candidates.size(), 2u);
    EXPECT_TRUE(d.candidates[1].at_bound) << d.summary();
    EXPECT_LT(d.confidence, two.suggest_below) << d.summary();  // the rule that would ask
    EXPECT_TRUE(d.suggestions.empty()) << d.summary();
    EXPECT_NE(d.suggestion_note.find("pinned"), std::string::npos) << d.suggestion_note;
    DiagnoseOptions always = two;
    always.suggest_always = true;
    fake::FakeSimulator sim2;
    EXPECT_FALSE(diagnose(base, ms, sim2, always).suggestions.empty());
  }
}

// Two effects hidden at once (rolling friction and cohesion both raise the heap; cohesion also
// opens the cup's packing). Cohesion alone, fitted to the heaps, lowers the cup too much, and a
// later diagnosis could not add rolling friction (the heaps already match): here no single effect
// explains the data, so the pair is fitted on the sum of their responses and run. Without pairs
// the verdict is cohesion alone at ~1.4e4 J/m^3 for 9000, chi2/dof 2.6 (p 0.007), and the
// diagnosis of that model says "consistent".
TEST(Diagnosis, TwoHiddenEffectsAreFoundTogether) {
  auto [base, truth] = rolling_friction_baseline_and_truth("off", "0.12");
  set_model_effect(truth, "effects.cohesion", "9000 J/m^3", "test");
  fake::FakeSimulator sim;
  const auto ms = synthesize(sim, truth, 0.02, 23);
  DiagnoseOptions o;
  o.suggest = false;
  const Diagnosis d = diagnose(base, ms, sim, o);
  ASSERT_FALSE(d.consistent) << d.summary();
  const CandidateResult& top = d.candidates.front();
  ASSERT_TRUE(top.with.has_value()) << d.summary();
  EXPECT_EQ(d.verdict, top.candidate.effect);
  EXPECT_NE(d.summary().find("two missing effects"), std::string::npos) << d.summary();
  EXPECT_GE(chi2_survival(top.comparison.chi2, top.comparison.dof), 0.01) << d.summary();
  EXPECT_EQ(top.comparison.dof, static_cast<int>(ms.size()) - 2);
  // The true pair is the verdict or named indistinguishable from it (on these data a lower
  // pill-pill friction with more cohesion moves the heaps and the cups alike), and is fitted
  // within its stated uncertainty.
  const CandidateResult* truth_pair = nullptr;
  for (const CandidateResult& r : d.candidates)
    if (r.candidate.effect == "rolling_friction+cohesion" ||
        r.candidate.effect == "cohesion+rolling_friction")
      truth_pair = &r;
  ASSERT_NE(truth_pair, nullptr) << d.summary();
  const auto& named = d.indistinguishable;
  EXPECT_TRUE(truth_pair == &top ||
              std::find(named.begin(), named.end(), truth_pair->candidate.effect) != named.end())
      << d.summary();
  const bool rf_first = truth_pair->candidate.effect == "rolling_friction+cohesion";
  const double mur = rf_first ? truth_pair->fitted : truth_pair->with->fitted;
  const double mur_std = rf_first ? truth_pair->fitted_std : truth_pair->with->std;
  const double coh = rf_first ? truth_pair->with->fitted : truth_pair->fitted;
  const double coh_std = rf_first ? truth_pair->with->std : truth_pair->fitted_std;
  EXPECT_LE(std::abs(mur - 0.12), 2.0 * mur_std + 1e-12) << d.summary();
  EXPECT_LE(std::abs(coh - 9000.0), 2.0 * coh_std + 1e-9) << d.summary();
  // --apply adds both: the new model is consistent with the data.
  const ParticleModel next = truth_pair->candidate.apply(base, truth_pair->fitted);
  ASSERT_TRUE(next.effects.rolling_friction.has_value());
  ASSERT_TRUE(next.effects.cohesion.has_value());
  const Diagnosis d2 = diagnose(next, ms, sim, o);
  EXPECT_TRUE(d2.consistent) << d2.summary();

  // Without pairs: one effect, which leaves the data unexplained.
  DiagnoseOptions single = o;
  single.pairs = false;
  fake::FakeSimulator sim1;
  const Diagnosis d1 = diagnose(base, ms, sim1, single);
  ASSERT_FALSE(d1.consistent);
  EXPECT_FALSE(d1.candidates.front().with.has_value());
  EXPECT_LT(
      chi2_survival(d1.candidates.front().comparison.chi2, d1.candidates.front().comparison.dof),
      0.01)
      << d1.summary();
}

// A mixture of several pill types whose lab sample held another share of each type than the model
// file says: size_distribution's mass-fraction candidate (the first type's share, the others in
// their ratios) is ranked first, fitted within its stated uncertainty, and the model it writes is
// consistent with the data.
TEST(Diagnosis, FindsAHiddenMixtureFraction) {
  const ParticleModel base =
      load_model(CLUMPKIT_SOURCE_DIR "/shapes/models/production.toml", CLUMPKIT_SOURCE_DIR);
  ASSERT_EQ(base.types.front().name, "A");
  ParticleModel truth = base;
  set_model_effect(truth, "effects.size_distribution.A", "0.7", "test");
  fake::FakeSimulator sim;
  const auto ms = synthesize(sim, truth, 0.02, 31);
  DiagnoseOptions o;
  o.suggest = false;
  const Diagnosis d = diagnose(base, ms, sim, o);
  ASSERT_FALSE(d.consistent) << d.summary();
  EXPECT_EQ(d.verdict, "size_distribution") << d.summary();
  const CandidateResult& top = d.candidates.front();
  EXPECT_NE(top.candidate.parameter.find("mass fraction of type A"), std::string::npos)
      << d.summary();
  EXPECT_LE(std::abs(top.fitted - 0.7), 2.0 * top.fitted_std + 1e-12)
      << top.fitted << " +/- " << top.fitted_std;
  EXPECT_GE(chi2_survival(top.comparison.chi2, top.comparison.dof), 0.01) << d.summary();
  const ParticleModel next = top.candidate.apply(base, top.fitted);
  EXPECT_NEAR(next.types[0].mass_fraction, top.fitted, 1e-12);
  // B and C keep the model file's 35:30.
  EXPECT_NEAR(next.types[1].mass_fraction / next.types[2].mass_fraction, 35.0 / 30.0, 1e-12);
  fake::FakeSimulator sim2;
  const Diagnosis d2 = diagnose(next, ms, sim2, o);
  EXPECT_TRUE(d2.consistent) << d2.summary();
}

// No verdict is not always a clean bill of health: a baseline that misses the data by more than
// noise usually does (p below the screen's 0.05) but not enough for a verdict (p >= 0.01) is
// called a marginal fit, with the leading candidates and their weights, not "consistent".
TEST(Diagnosis, AMarginalMisfitWithoutAVerdictIsNotCalledConsistent) {
  Diagnosis d;
  d.consistent = true;
  d.baseline.chi2 = 13.05;
  d.baseline.observables.resize(4);
  d.confidence = 0.02;
  for (const auto& [effect, weight] : {std::pair<std::string, double>{"cohesion", 0.57},
                                       {"particle_friction", 0.21},
                                       {"rolling_friction", 0.20}}) {
    CandidateResult c;
    c.candidate.effect = effect;
    c.weight = weight;
    d.candidates.push_back(c);
  }
  d.baseline_p = 0.011;
  const std::string marginal = d.summary();
  EXPECT_NE(marginal.find("no effect is named, but the model fits the data only marginally "
                          "(p = 0.011, baseline weight 0.02; a verdict needs p < 0.01"),
            std::string::npos)
      << marginal;
  EXPECT_NE(marginal.find("'cohesion' (weight 0.57), 'particle_friction' (weight 0.21), "
                          "'rolling_friction' (weight 0.20)"),
            std::string::npos)
      << marginal;
  EXPECT_EQ(marginal.find("consistent with the data"), std::string::npos) << marginal;
  d.baseline_p = 0.003;  // a misfit, but no candidate decisive
  const std::string missed = d.summary();
  EXPECT_NE(missed.find("no effect is named, though the model misses the data (p = 0.003"),
            std::string::npos)
      << missed;
  EXPECT_NE(missed.find("'cohesion' (weight 0.57)"), std::string::npos) << missed;
  d.baseline_p = 0.3;
  const std::string consistent = d.summary();
  EXPECT_NE(consistent.find("verdict: the model is consistent with the data"), std::string::npos)
      << consistent;
  d.baseline_p = 0.011;
  d.screen_only = true;  // a screen-only diagnosis saw p >= 0.05 after its screen
  EXPECT_NE(d.summary().find("consistent with the data"), std::string::npos);
}

// A 95 % interval that reaches past the strengths simulated for a candidate (by more than 5 %
// of their span) rests on the surrogate's straight continuation there: the interval is marked
// "*" and the verdict says so.
TEST(Diagnosis, AnIntervalPastTheRunsIsMarked) {
  CandidateResult r;
  r.candidate.effect = "cohesion";
  r.candidate.parameter = "SJKR energy density, pill-pill";
  r.candidate.unit = "J/m^3";
  r.fitted = 6275, r.fitted_std = 1950, r.fitted_lo = 1859, r.fitted_hi = 9821;
  r.runs_lo = 0, r.runs_hi = 8000;
  EXPECT_TRUE(r.interval_past_runs());
  EXPECT_EQ(interval_text(r), "1.86e+03 to 9.82e+03*");
  r.fitted_hi = 8300;  // within 5 % of the span past the last run: the tangent's job
  EXPECT_FALSE(r.interval_past_runs());
  EXPECT_EQ(interval_text(r), "1.86e+03 to 8.3e+03");
  r.fitted_lo = -500;  // past the first run
  EXPECT_TRUE(r.interval_past_runs());
  r.runs_hi = r.runs_lo;  // span unknown (discrete, pairs)
  EXPECT_FALSE(r.interval_past_runs());

  Diagnosis d;
  d.consistent = false;
  d.verdict = "cohesion";
  d.confidence = 0.9;
  d.baseline_p = 1e-4;
  r.fitted_lo = 1859, r.fitted_hi = 9821, r.runs_hi = 8000;
  d.candidates.push_back(r);
  const std::string s = d.summary();
  EXPECT_NE(s.find("note: the 95 % interval reaches past the strengths simulated for it (0 J/m^3 "
                   "to 8000 J/m^3)"),
            std::string::npos)
      << s;
  d.candidates.front().fitted_hi = 7000;
  EXPECT_EQ(d.summary().find("note: the 95 %"), std::string::npos);
}

// A hidden effect far along a response that levels off: after the ranking, runs at the far end
// of the leader's 95 % interval (DiagnoseOptions::end_runs) where it reaches past its runs. The
// stand-in's cohesion saturates (7.5e4 (1 - exp(-c / c0)) J/m^3 in its linear law), the truth
// 1.5e4 J/m^3 at 2.5 and at 5 times c0, 16 lab-noise draws each, without and with the end
// runs. Measured (the 95 % interval covering the truth; intervals still past the runs;
// cohesion the verdict; simulations over the 16 draws):
//   c0 6000:  without 15 covered, 9 past, 16 verdicts, 1552 runs; with 15, 0, 16, 1640;
//   c0 3000:  without  3 covered, 15 past, 12 verdicts, 1600 runs; with 9, 6, 12, 1736.
// The end runs come after the ranking, so the verdicts are the same. Far along the plateau
// (c0 3000) a parabola cannot follow the response, so the coverage stays short of 95 %; the
// intervals that still reach past the runs are marked "*".
TEST(Diagnosis, AnIntervalPastTheRunsGetsARunAtItsEnd) {
  const double truth_value = 1.5e4;
  for (const double c0 : {6000.0, 3000.0}) {
    int covered[2] = {0, 0}, past[2] = {0, 0}, verdicts[2] = {0, 0};
    long runs[2] = {0, 0};
    // Per draw, what the ranking made: the verdict, the leader and its fitted value and chi2.
    std::vector<std::tuple<std::string, std::string, double, double>> ranked[2];
    for (const int with_ends : {0, 1}) {
      for (int t = 0; t < 16; ++t) {
        ShapedCohesion sim([c0](double c) { return 7.5e4 * (1.0 - std::exp(-c / c0)); });
        sim.limit = 8e4;
        const auto [base, truth] = cohesion_baseline_and_truth("15000");
        const auto ms = synthesize(sim, truth, 0.02, 500 + t);
        DiagnoseOptions o;
        o.suggest = false;
        o.end_runs = with_ends ? 2 : 0;
        o.effects = {"cohesion", "rolling_friction", "particle_friction"};
        o.seed = 1 + 100 * t;
        const Diagnosis d = diagnose(base, ms, sim, o);
        verdicts[with_ends] += d.verdict == "cohesion";
        runs[with_ends] += d.simulations;
        ASSERT_FALSE(d.candidates.empty());
        const CandidateResult& top = d.candidates.front();
        ranked[with_ends].emplace_back(d.verdict, top.candidate.effect, top.fitted,
                                       top.comparison.chi2);
        if (with_ends) {
          EXPECT_LE(top.end_runs, 2);
        }
        for (const auto& c : d.candidates)
          if (c.candidate.effect == "cohesion" && !c.with) {
            covered[with_ends] += c.fitted_lo <= truth_value && truth_value <= c.fitted_hi;
            past[with_ends] += c.interval_past_runs();
            break;
          }
      }
      std::cout << "c0 " << c0 << (with_ends ? ", with" : ", without")
                << " the end runs: " << covered[with_ends] << " covered, " << past[with_ends]
                << " past the runs, " << verdicts[with_ends] << " verdicts of 16, "
                << runs[with_ends] << " runs\n";
    }
    // Without the end runs the problem shows; with them, fewer intervals rest on the tangent,
    // the coverage is no worse, and the verdicts are the same.
    EXPECT_GE(past[0], 6) << c0;
    EXPECT_LE(past[1], past[0] / 2) << c0;
    EXPECT_GE(covered[1], covered[0]) << c0;
    EXPECT_EQ(verdicts[1], verdicts[0]) << c0;
    EXPECT_EQ(ranked[1], ranked[0]) << c0 << ": the end runs changed a ranking";
    EXPECT_GE(covered[1], c0 == 6000.0 ? 13 : 7) << c0;
    EXPECT_GT(runs[1], runs[0]) << c0;
  }
}

// An end run past what the rigs can measure (here: above 1.6e4 J/m^3 the heap is too flat)
// fails; the interval then stops at the failed strength, and the candidate names the limit.
// Measured: 9 of the 16 draws of the c0 = 6000 case reported a limit.
TEST(Diagnosis, AnEndRunThatFailsBoundsTheIntervalAndNamesTheLimit) {
  int limits = 0;
  for (int t = 0; t < 16; ++t) {
    ShapedCohesion sim([](double c) { return 7.5e4 * (1.0 - std::exp(-c / 6000.0)); });
    sim.limit = 8e4;
    const auto [base, truth] = cohesion_baseline_and_truth("15000");
    const auto ms = synthesize(sim, truth, 0.02, 500 + t);
    sim.limit = 1.6e4;
    DiagnoseOptions o;
    o.suggest = false;
    o.effects = {"cohesion", "rolling_friction", "particle_friction"};
    o.seed = 1 + 100 * t;
    const Diagnosis d = diagnose(base, ms, sim, o);
    ASSERT_FALSE(d.candidates.empty());
    const CandidateResult& top = d.candidates.front();
    EXPECT_LE(top.fitted_hi, sim.lowest_failure) << t;
    if (top.limit.empty()) continue;
    ++limits;
    EXPECT_NE(top.limit.find("could not measure"), std::string::npos) << top.limit;
  }
  EXPECT_GE(limits, 5);
}
