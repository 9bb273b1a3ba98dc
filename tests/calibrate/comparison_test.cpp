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
