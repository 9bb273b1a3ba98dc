#include "ray_cache.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

namespace clumpkit::detail {

namespace {
std::uint64_t splitmix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}
double to_unit(std::uint64_t x) {
  return static_cast<double>(x >> 11) * 0x1.0p-53;
}
}  // namespace

RayCache::RayCache(const RaySolid& shape, const Eigen::AlignedBox3d& box, std::int64_t rays,
                   std::uint64_t seed, int threads) {
  const double per_axis = static_cast<double>(std::max<std::int64_t>(rays, 300)) / 3.0;
  const int nt = threads > 0 ? threads : omp_get_max_threads();
  threads_ = std::max(1, nt);
  for (int axis = 0; axis < 3; ++axis) {
    Axis& A = axes_[axis];
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const double lu = box.sizes()[u], lv = box.sizes()[v];
    A.nu = std::max(1, static_cast<int>(std::lround(std::sqrt(per_axis * lu / lv))));
    A.nv = std::max(1, static_cast<int>(std::lround(per_axis / A.nu)));
    A.u0 = box.min()[u];
    A.v0 = box.min()[v];
    A.du = lu / A.nu;
    A.dv = lv / A.nv;
    const int lines = A.nu * A.nv;
    A.pu.resize(lines);
    A.pv.resize(lines);
    std::vector<IntervalList> per(lines);
    const std::uint64_t base = splitmix(seed * 3 + static_cast<std::uint64_t>(axis) + 11);
#pragma omp parallel num_threads(nt)
    {
      Eigen::Vector3d o;
#pragma omp for schedule(dynamic, 16)
      for (int l = 0; l < lines; ++l) {
        const int i = l / A.nv, j = l % A.nv;
        const std::uint64_t r = splitmix(base + static_cast<std::uint64_t>(l));
        A.pu[l] = A.u0 + (i + to_unit(r)) * A.du;
        A.pv[l] = A.v0 + (j + to_unit(splitmix(r))) * A.dv;
        o[axis] = 0.0;
        o[u] = A.pu[l];
        o[v] = A.pv[l];
        shape.intervals(o, axis, per[l]);
      }
    }
    A.first.assign(lines + 1, 0);
    A.shape_length.assign(lines, 0.0);
    Moments m;
    for (int l = 0; l < lines; ++l) {
      A.first[l] = static_cast<int>(A.shape.size());
      A.shape.insert(A.shape.end(), per[l].begin(), per[l].end());
      A.shape_length[l] = total_length(per[l]);
      A.shape_total += A.shape_length[l];
      accumulate_moments(per[l], axis, A.pu[l], A.pv[l], A.du * A.dv, m);
    }
    A.first[lines] = static_cast<int>(A.shape.size());
    shape_volume_ += A.shape_total * A.du * A.dv / 3.0;
    m.m0 /= 3.0;
    m.m1 /= 3.0;
    m.m2 /= 3.0;
    shape_moments_ += m;
  }
}

RayCache::Eval RayCache::evaluate(const Spheres& spheres, bool moments,
                                  std::vector<double>* removal_cost) const {
  struct Chord {
    double t0, t1;
    int id;
  };
  // Sweep events along one line: position, kind (0 shape toggle, 1 sphere start, 2 sphere end).
  struct Event {
    double t;
    int kind, id;
  };
  // The three axes are independent estimates: computed in parallel into their own slots and
  // summed in a fixed order, so the result is bit-identical whatever the thread count.
  struct AxisOut {
    double xor_volume = 0.0, union_volume = 0.0;
    Moments m;
    std::vector<double> cost;
  };
  AxisOut outs[3];
#pragma omp parallel for num_threads(std::min(threads_, 3)) schedule(static, 1)
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<int> count, start;
    std::vector<Chord> items;
    std::vector<Event> ev;
    IntervalList uni;
    std::vector<double>& cost = outs[axis].cost;
    if (removal_cost) cost.assign(spheres.size(), 0.0);
    const Axis& A = axes_[axis];
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int lines = A.nu * A.nv;
    // Two passes of a counting sort: sphere chords bucketed by line.
    count.assign(lines + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      for (int id = 0; id < static_cast<int>(spheres.size()); ++id) {
        const Sphere& s = spheres[id];
        const int i0 =
            std::max(0, static_cast<int>(std::floor((s.center[u] - s.radius - A.u0) / A.du)));
        const int i1 = std::min(
            A.nu - 1, static_cast<int>(std::floor((s.center[u] + s.radius - A.u0) / A.du)));
        const int j0 =
            std::max(0, static_cast<int>(std::floor((s.center[v] - s.radius - A.v0) / A.dv)));
        const int j1 = std::min(
            A.nv - 1, static_cast<int>(std::floor((s.center[v] + s.radius - A.v0) / A.dv)));
        for (int i = i0; i <= i1; ++i)
          for (int j = j0; j <= j1; ++j) {
            const int l = i * A.nv + j;
            const double a = A.pu[l] - s.center[u], b = A.pv[l] - s.center[v];
            const double h2 = s.radius * s.radius - a * a - b * b;
            if (h2 <= 0) continue;
            if (pass == 0) {
              ++count[l + 1];
            } else {
              const double hh = std::sqrt(h2);
              items[start[l]++] = {s.center[axis] - hh, s.center[axis] + hh, id};
            }
          }
      }
      if (pass == 0) {
        for (int l = 0; l < lines; ++l) count[l + 1] += count[l];
        start.assign(count.begin(), count.end() - 1);
        items.resize(count[lines]);
      }
    }
    const double area = A.du * A.dv;
    double xor_len = A.shape_total, uni_len = 0.0;
    Moments m;
    for (int l = 0; l < lines; ++l) {
      if (count[l + 1] == count[l]) continue;
      ev.clear();
      for (int k = A.first[l]; k < A.first[l + 1]; ++k) {
        ev.push_back({A.shape[k].t0, 0, -1});
        ev.push_back({A.shape[k].t1, 0, -1});
      }
      for (int k = count[l]; k < count[l + 1]; ++k) {
        ev.push_back({items[k].t0, 1, items[k].id});
        ev.push_back({items[k].t1, 2, items[k].id});
      }
      std::sort(ev.begin(), ev.end(), [](const Event& a, const Event& b) { return a.t < b.t; });
      int cover = 0;
      long long idsum = 0;
      bool in_shape = false;
      double lu = 0.0, li = 0.0, open = 0.0;
      uni.clear();
      for (size_t k = 0; k < ev.size(); ++k) {
        if (k > 0) {
          const double len = ev[k].t - ev[k - 1].t;
          if (cover > 0) {
            lu += len;
            if (in_shape) li += len;
            if (cover == 1 && removal_cost) cost[idsum] += in_shape ? len : -len;
          }
        }
        const Event& x = ev[k];
        if (x.kind == 0) {
          in_shape = !in_shape;
        } else if (x.kind == 1) {
          if (cover++ == 0) open = x.t;
          idsum += x.id;
        } else {
          if (--cover == 0 && moments) uni.push_back({open, x.t});
          idsum -= x.id;
        }
      }
      // |S xor U| = |S| + |U| - 2 |S and U|; |S| is already in xor_len.
      xor_len += lu - 2.0 * li;
      uni_len += lu;
      if (moments) accumulate_moments(uni, axis, A.pu[l], A.pv[l], area, m);
    }
    outs[axis].xor_volume = xor_len * area / 3.0;
    outs[axis].union_volume = uni_len * area / 3.0;
    for (double& c : cost) c *= area / 3.0;
    if (moments) {
      m.m0 /= 3.0;
      m.m1 /= 3.0;
      m.m2 /= 3.0;
      outs[axis].m = m;
    }
  }
  Eval e;
  if (removal_cost) removal_cost->assign(spheres.size(), 0.0);
  for (const AxisOut& o : outs) {
    e.xor_volume += o.xor_volume;
    e.union_volume += o.union_volume;
    if (moments) e.union_moments += o.m;
    if (removal_cost)
      for (size_t k = 0; k < spheres.size(); ++k) (*removal_cost)[k] += o.cost[k];
  }
  return e;
}

}  // namespace clumpkit::detail
