#include "distance_grid.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace clumpkit::detail {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

// 1-D squared distance transform: d[p] = min_q (h^2 (p - q)^2 + f[q]) (Felzenszwalb and
// Huttenlocher 2012), with infinite samples ignored.
void dt1d(const std::vector<double>& f, std::vector<double>& d, double h2, std::vector<int>& v,
          std::vector<double>& z) {
  const int n = static_cast<int>(f.size());
  d.assign(n, kInf);
  v.resize(n);
  z.resize(n + 1);
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == kInf) continue;
    const double fq = f[q] / h2;
    while (k >= 0) {
      const double fv = f[v[k]] / h2;
      const double s =
          ((fq + q * static_cast<double>(q)) - (fv + v[k] * static_cast<double>(v[k]))) /
          (2.0 * (q - v[k]));
      if (s <= z[k]) {
        --k;
      } else {
        ++k;
        v[k] = q;
        z[k] = s;
        z[k + 1] = kInf;
        break;
      }
    }
    if (k < 0) {
      k = 0;
      v[0] = q;
      z[0] = -kInf;
      z[1] = kInf;
    }
  }
  if (k < 0) return;
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const double dq = q - v[j];
    d[q] = h2 * dq * dq + f[v[j]];
  }
}
}  // namespace

double DistanceGrid::sample(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d g = (p - origin) / h;
  Eigen::Vector3d gc = g;
  double extra = 0.0;
  for (int a = 0; a < 3; ++a) gc[a] = std::clamp(g[a], 0.0, n[a] - 1.0);
  extra = (g - gc).norm() * h;
  int i0[3];
  double t[3];
  for (int a = 0; a < 3; ++a) {
    i0[a] = std::min(static_cast<int>(gc[a]), n[a] - 2);
    t[a] = gc[a] - i0[a];
  }
  double v = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
    const double w = (di ? t[0] : 1 - t[0]) * (dj ? t[1] : 1 - t[1]) * (dk ? t[2] : 1 - t[2]);
    v += w * sdf[index(i0[0] + di, i0[1] + dj, i0[2] + dk)];
  }
  return v + extra;
}

DistanceGrid build_distance_grid(const RaySolid& solid, int cells, int threads) {
  DistanceGrid g;
  const Eigen::AlignedBox3d b = solid.bounds();
  g.h = b.sizes().maxCoeff() / std::max(4, cells);
  for (int a = 0; a < 3; ++a) g.n[a] = static_cast<int>(std::ceil(b.sizes()[a] / g.h)) + 4;
  g.origin = b.center() - 0.5 * g.h * (g.n.cast<double>() - Eigen::Vector3d::Ones());
  const std::int64_t total = g.size();
  std::vector<double> best(total, kInf);
  g.inside.assign(total, 0);
  const int nt = threads > 0 ? threads : omp_get_max_threads();

  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, w = (axis + 2) % 3;
    std::vector<double> f(total, kInf);  // squared 1-D distance along `axis`
    auto idx = [&](int a_i, int u_i, int w_i) {
      int ijk[3];
      ijk[axis] = a_i;
      ijk[u] = u_i;
      ijk[w] = w_i;
      return g.index(ijk[0], ijk[1], ijk[2]);
    };
#pragma omp parallel num_threads(nt)
    {
      IntervalList list;
#pragma omp for schedule(dynamic, 4)
      for (int wi = 0; wi < g.n[w]; ++wi)
        for (int ui = 0; ui < g.n[u]; ++ui) {
          Eigen::Vector3d o = g.center(0, 0, 0);
          o[u] += ui * g.h;
          o[w] += wi * g.h;
          o[axis] = 0.0;
          solid.intervals(o, axis, list);
          if (list.empty()) continue;
          for (int ai = 0; ai < g.n[axis]; ++ai) {
            const double x = g.origin[axis] + ai * g.h;
            double d = kInf;
            bool in = false;
            for (const Interval& iv : list) {
              d = std::min({d, std::abs(x - iv.t0), std::abs(x - iv.t1)});
              in = in || (x > iv.t0 && x < iv.t1);
            }
            f[idx(ai, ui, wi)] = d * d;
            if (axis == 0 && in) g.inside[idx(ai, ui, wi)] = 1;
          }
        }
    }
    // Spread over u, then w.
    for (int pass = 0; pass < 2; ++pass) {
      const int along = pass == 0 ? u : w;
      const int o1 = axis, o2 = pass == 0 ? w : u;
#pragma omp parallel num_threads(nt)
      {
        std::vector<double> line, out, z;
        std::vector<int> v;
#pragma omp for schedule(static)
        for (int b2 = 0; b2 < g.n[o2]; ++b2)
          for (int b1 = 0; b1 < g.n[o1]; ++b1) {
            line.resize(g.n[along]);
            auto at = [&](int s) {
              int ijk[3];
              ijk[along] = s;
              ijk[o1] = b1;
              ijk[o2] = b2;
              return g.index(ijk[0], ijk[1], ijk[2]);
            };
            for (int s = 0; s < g.n[along]; ++s) line[s] = f[at(s)];
            dt1d(line, out, g.h * g.h, v, z);
            for (int s = 0; s < g.n[along]; ++s) f[at(s)] = out[s];
          }
      }
    }
    for (std::int64_t i = 0; i < total; ++i) best[i] = std::min(best[i], f[i]);
  }
  g.sdf.resize(total);
  const double far = 10.0 * g.h * g.n.maxCoeff();
  for (std::int64_t i = 0; i < total; ++i) {
    const double d = best[i] == kInf ? far : std::sqrt(best[i]);
    g.sdf[i] = static_cast<float>(g.inside[i] ? -d : d);
  }
  return g;
}

}  // namespace clumpkit::detail
