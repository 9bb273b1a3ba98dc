// The diagnosis's response surrogate (lib/src/calibrate/surrogate.hpp): the run variance it
// weighs its points by and its curves, in closed form.
#include <gtest/gtest.h>

#include "calibrate/surrogate.hpp"
#include "clumpkit/calibrate/measurements.hpp"

namespace clumpkit::calibrate {
namespace {

Measurement heap(const std::string& plate) {
  Measurement m;
  m.rig = "angle_of_repose";
  m.sample = "A";
  m.setting = {{"plate", plate}};
  m.quantity = "angle";
  m.unit = "deg";
  return m;
}

Measurement cup() {
  Measurement m;
  m.rig = "bulk_density";
  m.sample = "A";
  m.setting = {{"wall", "organic_glass"}};
  m.quantity = "bulk_density";
  m.unit = "kg/m^3";
  return m;
}

// A baseline far off at t = 0 and a refinement cluster at t = 10.0-10.3 (two repeats each):
// only the cluster's triples count (within a quarter of the span 10.3). `cluster` holds each
// observable's four cluster means.
Surrogate clustered(const std::map<std::string, std::vector<double>>& cluster) {
  Surrogate s;
  Values base;
  for (const auto& [key, ys] : cluster) base[key] = {0.0, 0.1, 2};
  s.add(0.0, base);
  for (int i = 0; i < 4; ++i) {
    Values v;
    for (const auto& [key, ys] : cluster) v[key] = {ys[i], 0.1, 2};
    s.add(10.0 + 0.1 * i, v);
  }
  return s;
}

// The pooled spread: one run's std 0.1 for every observable.
Values pooled(const std::vector<std::string>& keys) {
  Values v;
  for (const auto& k : keys) v[k] = {0.0, 0.1, 2};
  return v;
}

TEST(Surrogate, PointsOnALineScatterAsThePooledSpreadSays) {
  const std::string k = heap("abs_plastic").key();
  Surrogate s = clustered({{k, {1.0, 1.1, 1.2, 1.3}}});
  EXPECT_EQ(s.scatter_var(k), 0.0) << "not aimed: unknown";
  s.aim(10.0, pooled({k}));
  EXPECT_DOUBLE_EQ(s.scatter_var(k), 0.01);
}

TEST(Surrogate, AScatterWithinThePooledSpreadKeepsIt) {
  const std::string k = heap("abs_plastic").key();
  // +/-0.05 about 2: each pseudo-residual 0.1, against sqrt(0.01 * 0.75) = 0.087 expected.
  Surrogate s = clustered({{k, {1.95, 2.05, 1.95, 2.05}}});
  s.aim(10.0, pooled({k}));
  EXPECT_DOUBLE_EQ(s.scatter_var(k), 0.01);
}

TEST(Surrogate, MeansThatScatterMoreThanTheirRepeatsAreWeighedByTheirScatter) {
  const std::string k = heap("abs_plastic").key();
  // Means alternating 1, 3, 1, 3: each middle point is 2 off the line through its neighbours,
  // whose variance is (1/4 + 1/4 + 1) / 2 = 0.75 of one run's: one run's variance 4 / 0.75.
  Surrogate s = clustered({{k, {1.0, 3.0, 1.0, 3.0}}});
  s.aim(10.0, pooled({k}));
  EXPECT_NEAR(s.scatter_var(k), 16.0 / 3.0, 1e-9);
  // The noise of a simulated mean through the surrogate follows (never below it / base_n).
  EXPECT_GE(s.noise_var(k, 0.01, 2), 16.0 / 3.0 / 2.0 - 1e-9);
}

TEST(Surrogate, TheScatterIsPooledOverTheObservablesOfAFamily) {
  const Measurement abs = heap("abs_plastic"), steel = heap("galvanized_steel");
  const Measurement glass = cup();
  SpreadPool pool({abs, steel, glass});
  Surrogate s = clustered({{abs.key(), {1.0, 3.0, 1.0, 3.0}},
                           {steel.key(), {1.0, 1.1, 1.2, 1.3}},
                           {glass.key(), {500.0, 501.0, 502.0, 503.0}}});
  s.aim(10.0, pooled({abs.key(), steel.key(), glass.key()}), &pool);
  // The heaps' four pseudo-residuals: two of 4 / 0.75 / 0.01 each, two of 0: the mean factor
  // is 16 / 3 / 0.01 / 2 on one run's variance 0.01, for both plates.
  EXPECT_NEAR(s.scatter_var(abs.key()), 8.0 / 3.0, 1e-9);
  EXPECT_NEAR(s.scatter_var(steel.key()), 8.0 / 3.0, 1e-9);
  // The cup is another family: its points lie on a line.
  EXPECT_DOUBLE_EQ(s.scatter_var(glass.key()), 0.01);
  // Without the pool's families each observable is its own.
  s.aim(10.0, pooled({abs.key(), steel.key(), glass.key()}));
  EXPECT_NEAR(s.scatter_var(abs.key()), 16.0 / 3.0, 1e-9);
  EXPECT_DOUBLE_EQ(s.scatter_var(steel.key()), 0.01);
}

TEST(Surrogate, ARedrawnCopyKeepsTheOriginalsScatter) {
  const std::string k = heap("abs_plastic").key();
  Surrogate s = clustered({{k, {1.0, 3.0, 1.0, 3.0}}});
  s.aim(10.0, pooled({k}));
  std::mt19937_64 rng(3);
  const Surrogate r = s.redrawn(rng);
  EXPECT_NEAR(r.scatter_var(k), 16.0 / 3.0, 1e-9);
}

}  // namespace
// A curve evaluates its observable as value() does: the parabola through three points
// (y = 1 + t^2 at t = 1, 2, 3) between them, its tangent beyond them; and chi2_of from the
// curves equals chi2_of from the surrogate.
TEST(Surrogate, ACurveIsTheSurrogatesValue) {
  const std::string k = heap("abs_plastic").key(), kc = cup().key();
  Surrogate s;
  for (double t : {1.0, 2.0, 3.0})
    s.add(t, {{k, {1.0 + t * t, 0.1, 2}}, {kc, {500.0 - t, 1.0, 2}}});
  const Surrogate::Curve c = s.curve(k);
  for (double t : {0.0, 1.0, 1.5, 2.5, 3.0, 4.0}) EXPECT_EQ(c(t), s.value(k, t)) << t;
  EXPECT_NEAR(c(2.5), 1.0 + 2.5 * 2.5, 1e-12);
  EXPECT_NEAR(c(4.0), 10.0 + 6.0, 1e-12) << "beyond the points: the tangent at t = 3";
  EXPECT_NEAR(c(0.0), 2.0 - 2.0, 1e-12) << "before them: the tangent at t = 1";
  Measurement mh = heap("abs_plastic"), mc = cup();
  mh.value = 8.0, mc.value = 498.0;
  const std::vector<Measurement> ms = {mh, mc};
  const std::vector<double> var = {0.5, 2.0};
  const std::vector<Surrogate::Curve> curves = {s.curve(k), s.curve(kc)};
  for (double t : {0.0, 1.3, 3.5}) EXPECT_EQ(chi2_of(ms, var, curves, t), chi2_of(ms, var, s, t));
  EXPECT_NEAR(chi2_of(ms, var, s, 3.0), (10.0 - 8.0) * (10.0 - 8.0) / 0.5 + 1.0 / 2.0, 1e-9);
}

}  // namespace clumpkit::calibrate
