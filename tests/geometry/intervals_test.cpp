#include "clumpkit/geometry/intervals.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace clumpkit;

namespace {
IntervalList random_list(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 10.0);
  IntervalList l;
  const int n = static_cast<int>(rng() % 6);
  for (int i = 0; i < n; ++i) {
    double a = u(rng), b = u(rng);
    if (a > b) std::swap(a, b);
    if (b > a) l.push_back({a, b});
  }
  merge_intervals(l);
  return l;
}
bool inside(const IntervalList& l, double t) {
  for (const auto& iv : l)
    if (t > iv.t0 && t < iv.t1) return true;
  return false;
}
}  // namespace

// Seeded property test: merged, xor and intersection lists agree with point membership.
TEST(Intervals, SetOperationsMatchPointMembership) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 500; ++trial) {
    const IntervalList a = random_list(rng), b = random_list(rng);
    for (size_t i = 1; i < a.size(); ++i) EXPECT_GT(a[i].t0, a[i - 1].t1);
    const IntervalList x = xor_intervals(a, b), n = intersect_intervals(a, b);
    for (int k = 0; k < 200; ++k) {
      const double t = 10.0 * (k + 0.37) / 200.0;
      EXPECT_EQ(inside(x, t), inside(a, t) != inside(b, t));
      EXPECT_EQ(inside(n, t), inside(a, t) && inside(b, t));
    }
    // |A xor B| = |A| + |B| - 2 |A and B|
    EXPECT_NEAR(total_length(x), total_length(a) + total_length(b) - 2 * total_length(n), 1e-12);
  }
}
