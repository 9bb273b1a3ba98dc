#include "clumpkit/geometry/ray_moments.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace clumpkit {

Moments& Moments::operator+=(const Moments& o) {
  m0 += o.m0;
  m1 += o.m1;
  m2 += o.m2;
  return *this;
}

Estimate estimate(const std::vector<double>& samples) {
  Estimate e;
  const size_t n = samples.size();
  if (n == 0) return e;
  double mean = 0.0;
  for (double s : samples) mean += s;
  mean /= static_cast<double>(n);
  e.value = mean;
  if (n < 2) return e;
  double var = 0.0;
  for (double s : samples) var += (s - mean) * (s - mean);
  var /= static_cast<double>(n - 1);
  // Two-sided 95 % Student t quantiles for n - 1 degrees of freedom.
  static const double t975[] = {0,     12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365,
                                2.306, 2.262,  2.228, 2.201, 2.179, 2.160, 2.145, 2.131,
                                2.120, 2.110,  2.101, 2.093, 2.086, 2.080, 2.074, 2.069,
                                2.064, 2.060,  2.056, 2.052, 2.048, 2.045, 2.042};
  const size_t dof = n - 1;
  const double t = dof < std::size(t975) ? t975[dof] : 1.96;
  e.ci95 = t * std::sqrt(var / static_cast<double>(n));
  return e;
}

namespace {
// SplitMix64: a counter-based generator so that each grid row's jitter depends only on
// (seed, axis, replicate, row), never on which thread ran it.
std::uint64_t splitmix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}
struct RowRng {
  std::uint64_t state;
  double uniform() {
    state = splitmix(state);
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  }
};

}  // namespace

void accumulate_moments(const IntervalList& list, int axis, double pu, double pv, double area,
                        Moments& m) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  for (const Interval& iv : list) {
    const double a = iv.t0, b = iv.t1;
    const double l = b - a;
    const double s1 = 0.5 * (b * b - a * a);
    const double s2 = (b * b * b - a * a * a) / 3.0;
    m.m0 += area * l;
    m.m1[axis] += area * s1;
    m.m1[u] += area * pu * l;
    m.m1[v] += area * pv * l;
    m.m2(axis, axis) += area * s2;
    m.m2(u, u) += area * pu * pu * l;
    m.m2(v, v) += area * pv * pv * l;
    const double au = area * pu * s1, av = area * pv * s1, uv = area * pu * pv * l;
    m.m2(axis, u) += au;
    m.m2(u, axis) += au;
    m.m2(axis, v) += av;
    m.m2(v, axis) += av;
    m.m2(u, v) += uv;
    m.m2(v, u) += uv;
  }
}

std::vector<std::vector<Moments>> integrate_rays(const Eigen::AlignedBox3d& box_in, int nchannels,
                                                 const RayChannels& channels,
                                                 const RaySamplingOptions& opt) {
  if (opt.rays <= 0) throw std::invalid_argument("integrate_rays: rays must be positive");
  const int reps = std::max(2, opt.replicates);
  // Pad the box slightly so that no part of a solid lies exactly on the sampling boundary.
  Eigen::AlignedBox3d box = box_in;
  const double pad = 1e-9 * std::max(1.0, box.diagonal().norm());
  box.min().array() -= pad;
  box.max().array() += pad;
  const double per_grid = static_cast<double>(opt.rays) / (3.0 * reps);

  std::vector<std::vector<Moments>> result(nchannels, std::vector<Moments>(3 * reps));
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const double lu = box.sizes()[u], lv = box.sizes()[v];
    // Cells as close to square as the budget allows.
    int nu = std::max(1, static_cast<int>(std::lround(std::sqrt(per_grid * lu / lv))));
    int nv = std::max(1, static_cast<int>(std::lround(per_grid / nu)));
    const double du = lu / nu, dv = lv / nv, area = du * dv;
    for (int rep = 0; rep < reps; ++rep) {
      std::vector<std::vector<Moments>> rows(nu, std::vector<Moments>(nchannels));
      const std::uint64_t base =
          splitmix(opt.seed ^ splitmix(static_cast<std::uint64_t>(axis * 1000 + rep + 1)));
      const int threads = opt.threads > 0 ? opt.threads : omp_get_max_threads();
#pragma omp parallel num_threads(threads)
      {
        std::vector<IntervalList> ch(nchannels);
        Eigen::Vector3d origin;
#pragma omp for schedule(dynamic, 4)
        for (int i = 0; i < nu; ++i) {
          RowRng rng{splitmix(base + static_cast<std::uint64_t>(i))};
          for (int j = 0; j < nv; ++j) {
            const double pu = box.min()[u] + (i + rng.uniform()) * du;
            const double pv = box.min()[v] + (j + rng.uniform()) * dv;
            origin[axis] = 0.0;
            origin[u] = pu;
            origin[v] = pv;
            for (auto& c : ch) c.clear();
            channels(origin, axis, ch);
            for (int c = 0; c < nchannels; ++c)
              accumulate_moments(ch[c], axis, pu, pv, area, rows[i][c]);
          }
        }
      }
      // Sum rows in a fixed order: bit-identical whatever the thread count.
      for (int c = 0; c < nchannels; ++c)
        for (int i = 0; i < nu; ++i) result[c][axis * reps + rep] += rows[i][c];
    }
  }
  return result;
}

std::vector<Moments> integrate_solid(const RaySolid& solid, const RaySamplingOptions& options) {
  auto r = integrate_rays(
      solid.bounds(), 1,
      [&](const Eigen::Vector3d& o, int axis, std::vector<IntervalList>& ch) {
        solid.intervals(o, axis, ch[0]);
      },
      options);
  return r[0];
}

Moments mean_moments(const std::vector<Moments>& samples) {
  Moments m;
  for (const Moments& s : samples) m += s;
  const double inv = samples.empty() ? 0.0 : 1.0 / static_cast<double>(samples.size());
  m.m0 *= inv;
  m.m1 *= inv;
  m.m2 *= inv;
  return m;
}

}  // namespace clumpkit
