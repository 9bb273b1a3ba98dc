#include "clumpkit/calibrate/comparison.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace clumpkit;

TEST(Comparison, ZScoresAndChiSquareByHand) {
  const auto m = parse_measurements(
      "rig,sample,setting,quantity,value,std,n,unit\n"
      "bulk_density,A,,bulk_density,700,6,4,kg/m^3\n"
      "angle_of_repose,A,,angle,25,1,1,deg\n",
      "m.csv");
  std::map<std::string, SimulatedValue> sim;
  sim[m[0].key()] = {709.0, 8.0, 4};  // sigma = sqrt(36/4 + 64/4) = 5 -> z = 1.8
  sim[m[1].key()] = {28.0, 0.0, 1};   // sigma = 1 -> z = 3
  const Comparison c = compare(m, sim);
  ASSERT_EQ(c.observables.size(), 2u);
  EXPECT_NEAR(c.observables[0].z, 1.8, 1e-12);
  EXPECT_TRUE(c.observables[0].pass);
  EXPECT_NEAR(c.observables[1].z, 3.0, 1e-12);
  EXPECT_FALSE(c.observables[1].pass);
  EXPECT_NEAR(c.observables[1].rel_error, 3.0 / 25.0, 1e-12);
  EXPECT_NEAR(c.chi2, 1.8 * 1.8 + 9.0, 1e-12);
  EXPECT_EQ(c.dof, 2);
  const Comparison k1 = compare(m, sim, 1);
  EXPECT_EQ(k1.dof, 1);
  EXPECT_NEAR(k1.bic - k1.chi2, std::log(2.0), 1e-12);
}

// Seeded property: when simulation and lab sample the same distribution, chi2/dof is ~1.
TEST(Comparison, ConsistentModelGivesChiSquarePerDofNearOne) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::string csv = "rig,sample,setting,quantity,value,std,n,unit\n";
  std::map<std::string, SimulatedValue> sim;
  std::vector<double> truths;
  const int n = 400;
  for (int i = 0; i < n; ++i) {
    const double truth = 20 + i * 0.01, sd = 0.5;
    double mean = 0;
    for (int k = 0; k < 3; ++k) mean += truth + sd * noise(rng);
    mean /= 3;
    csv += "discharge,mix,rpm=" + std::to_string(i + 1) + ",mass_flow," + std::to_string(mean) +
           ",0.5,3,kg/s\n";
    truths.push_back(truth);
  }
  const auto m = parse_measurements(csv, "m.csv");
  for (size_t i = 0; i < m.size(); ++i) sim[m[i].key()] = {truths[i], 0.0, 1};
  const Comparison c = compare(m, sim);
  EXPECT_NEAR(c.chi2_per_dof, 1.0, 0.25);
}

TEST(SpreadPool, PoolsVariancesWeightedByDegreesOfFreedom) {
  SpreadPool pool;
  // (2-1)*1^2 + (4-1)*3^2 = 28 over 4 degrees of freedom -> s = sqrt(7).
  pool.add({{"a", {10.0, 1.0, 2}}, {"single", {5.0, 0.0, 1}}});
  pool.add({{"a", {12.0, 3.0, 4}}});
  EXPECT_EQ(pool.dof("a"), 4);
  EXPECT_EQ(pool.dof("single"), 0);  // one repeat carries no spread
  const auto p = pool.pooled({{"a", {11.0, 0.1, 2}}, {"single", {5.0, 0.0, 1}}, {"b", {1, 2, 3}}});
  EXPECT_NEAR(p.at("a").std, std::sqrt(7.0), 1e-12);
  EXPECT_EQ(p.at("a").mean, 11.0);  // means and n are the model's own
  EXPECT_EQ(p.at("a").n, 2);
  EXPECT_EQ(p.at("single").std, 0.0);
  EXPECT_EQ(p.at("b").std, 2.0);  // unknown to the pool: unchanged
}

// Seeded property: with two repeats per model the spread of one model is often several times too
// small; pooled over 60 models (60 degrees of freedom, ~9 % standard error) it is within 25 % of
// the true spread.
TEST(SpreadPool, PooledSpreadOfManyTwoRepeatModelsIsNearTheTruth) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 2.0);
  SpreadPool pool;
  int tiny = 0;
  for (int model = 0; model < 60; ++model) {
    const double a = 30 + model + noise(rng), b = 30 + model + noise(rng);
    const SimulatedValue v = summarize({a, b});
    tiny += v.std < 0.5 * 2.0;
    pool.add({{"angle", v}});
  }
  EXPECT_GT(tiny, 0);  // the trap the pool avoids
  EXPECT_NEAR(pool.pooled({{"angle", {0, 0, 2}}}).at("angle").std, 2.0, 0.5);
}
