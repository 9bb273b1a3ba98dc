#include "clumpkit/calibrate/diagnosis.hpp"

#include <gtest/gtest.h>

#include <random>

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

// Measurements from a truth model: the template's rows, values = simulation with a seed the
// diagnosis never uses, plus lab noise of relative size `rel`.
std::vector<Measurement> synthesize(Simulator& sim, const ParticleModel& truth, double rel,
                                    std::uint64_t seed) {
  const std::string csv =
      "rig,sample,setting,quantity,value,std,n,unit\n"
      "bulk_density,A,wall=organic_glass,bulk_density,1,1,3,kg/m^3\n"
      "bulk_density,A,wall=galvanized_steel,bulk_density,1,1,3,kg/m^3\n"
      "bulk_density,A,wall=abs_plastic,bulk_density,1,1,3,kg/m^3\n"
      "angle_of_repose,A,plate=galvanized_steel,angle,1,1,3,deg\n"
      "angle_of_repose,A,plate=abs_plastic,angle,1,1,3,deg\n"
      "discharge,A,rpm=10,pocket_mass,1,1,3,kg\n"
      "discharge,A,rpm=15,pocket_mass,1,1,3,kg\n"
      "discharge,A,rpm=30,pocket_mass,1,1,3,kg\n";
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
    o.suggest = true;
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
  }
  EXPECT_LE(sum_chi2_per_dof / std::size(cases), 1.5);
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

TEST(Diagnosis, ChiSquareSurvivalMatchesKnownValues) {
  EXPECT_NEAR(chi2_survival(3.841, 1), 0.05, 1e-4);
  EXPECT_NEAR(chi2_survival(18.307, 10), 0.05, 1e-4);
  EXPECT_NEAR(chi2_survival(10.0, 10), 0.4405, 1e-4);
  EXPECT_NEAR(chi2_survival(0.0, 3), 1.0, 1e-12);
}
