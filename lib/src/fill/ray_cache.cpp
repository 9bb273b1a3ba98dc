#include "ray_cache.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <numbers>

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
// Sweep events along a line: position and a key that orders ties (see evaluate). Sorting on
// (t, key) is a total order, so std::sort gives the same sequence whatever the input order.
struct Event {
  double t;
  int key;
  bool operator<(const Event& o) const { return t < o.t || (t == o.t && key < o.key); }
};
// Insertion sort: linear on the nearly sorted chord ends the callers produce (chords generated
// in order of the spheres' centres along the line).
void sort_nearly_sorted(std::vector<double>& v) {
  for (size_t k = 1; k < v.size(); ++k) {
    const double x = v[k];
    size_t m = k;
    for (; m > 0 && x < v[m - 1]; --m) v[m] = v[m - 1];
    v[m] = x;
  }
}
// Sphere indices in order of their centres along each axis (ties by index).
void axis_orders(const Spheres& spheres, std::vector<int> (&order)[3]) {
  for (int axis = 0; axis < 3; ++axis) {
    order[axis].resize(spheres.size());
    for (size_t k = 0; k < spheres.size(); ++k) order[axis][k] = static_cast<int>(k);
    std::sort(order[axis].begin(), order[axis].end(), [&](int a, int b) {
      const double ca = spheres[a].center[axis], cb = spheres[b].center[axis];
      return ca < cb || (ca == cb && a < b);
    });
  }
}
// Walks the events of one line in increasing position: the sorted shape boundaries (toggles),
// chord starts and chord ends; ties are taken in that order (shape, start, end), so the cover
// count never drops below its value on either side of the tie. Calls f(t, kind) with kind 0, 1,
// 2; stops after the last end if `to_last_end` (beyond it nothing is covered).
template <class F>
void merge_events(const double* bnd, size_t nb, const std::vector<double>& st,
                  const std::vector<double>& en, bool to_last_end, F&& f) {
  size_t ib = 0, is = 0, ie = 0;
  const size_t ns = st.size(), ne = en.size();
  while (ie < ne || (!to_last_end && (ib < nb || is < ns))) {
    const bool hb = ib < nb, hs = is < ns, he = ie < ne;
    if (hb && (!hs || bnd[ib] <= st[is]) && (!he || bnd[ib] <= en[ie])) {
      f(bnd[ib++], 0);
    } else if (hs && (!he || st[is] <= en[ie])) {
      f(st[is++], 1);
    } else {
      f(en[ie++], 2);
    }
  }
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
  // Work is split into fixed blocks of lines (kBlocks per axis, independent of the thread count),
  // each computed into its own slot and summed in a fixed order: the result is bit-identical
  // whatever the number of threads, and two threads share three axes evenly.
  constexpr int kBlocks = 8;
  struct BlockOut {
    double xor_len = 0.0, uni_len = 0.0;
    Moments m;
    std::vector<double> cost;
  };
  std::vector<BlockOut> outs(3 * kBlocks);
  // Chords are generated in order of the spheres' centres along the line, so their starts and
  // their ends are each nearly sorted already.
  std::vector<int> order[3];
  axis_orders(spheres, order);
  const bool detailed = moments || removal_cost;
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 1)
  for (int task = 0; task < 3 * kBlocks; ++task) {
    const int axis = task / kBlocks, block = task % kBlocks;
    std::vector<int> count, start;
    std::vector<Chord> items;
    std::vector<Event> ev;
    std::vector<double> st, en, bnd;
    IntervalList uni;
    std::vector<double>& cost = outs[task].cost;
    if (removal_cost) cost.assign(spheres.size(), 0.0);
    const Axis& A = axes_[axis];
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int ib = static_cast<int>(static_cast<std::int64_t>(A.nu) * block / kBlocks);
    const int ie = static_cast<int>(static_cast<std::int64_t>(A.nu) * (block + 1) / kBlocks);
    if (ib >= ie) continue;
    const int lbase = ib * A.nv, lines = (ie - ib) * A.nv;
    // Two passes of a counting sort: sphere chords bucketed by line (local index l - lbase).
    count.assign(lines + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      for (const int id : order[axis]) {
        const Sphere& s = spheres[id];
        const int i0 =
            std::max(ib, static_cast<int>(std::floor((s.center[u] - s.radius - A.u0) / A.du)));
        const int i1 =
            std::min(ie - 1, static_cast<int>(std::floor((s.center[u] + s.radius - A.u0) / A.du)));
        if (i0 > i1) continue;
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
              ++count[l - lbase + 1];
            } else {
              const double hh = std::sqrt(h2);
              items[start[l - lbase]++] = {s.center[axis] - hh, s.center[axis] + hh, id};
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
    double xor_len = 0.0, uni_len = 0.0;
    Moments m;
    for (int ll = 0; ll < lines; ++ll) {
      if (count[ll + 1] == count[ll]) continue;
      const int l = ll + lbase;
      const Chord* chords = items.data() + count[ll];
      const int nc = count[ll + 1] - count[ll];
      double lu = 0.0, li = 0.0;
      if (!detailed) {
        // Union and intersection lengths only: the chord starts and ends sorted separately and
        // merged with the shape's boundaries. The same segments are summed in the same order as
        // in the full sweep below, so the sums are the same to the bit.
        st.resize(nc);
        en.resize(nc);
        for (int k = 0; k < nc; ++k) {
          st[k] = chords[k].t0;
          en[k] = chords[k].t1;
        }
        sort_nearly_sorted(st);
        sort_nearly_sorted(en);
        bnd.clear();
        for (int k = A.first[l]; k < A.first[l + 1]; ++k) {
          bnd.push_back(A.shape[k].t0);
          bnd.push_back(A.shape[k].t1);
        }
        int cover = 0;
        bool in_shape = false, started = false;
        double prev = 0.0;
        merge_events(bnd.data(), bnd.size(), st, en, true, [&](double t, int kind) {
          if (started && cover > 0) {
            const double len = t - prev;
            lu += len;
            if (in_shape) li += len;
          }
          started = true;
          prev = t;
          if (kind == 0)
            in_shape = !in_shape;
          else
            cover += kind == 1 ? 1 : -1;
        });
        xor_len += lu - 2.0 * li;
        uni_len += lu;
        continue;
      }
      // The full sweep (moments, removal costs). Event keys: 0 a shape boundary, 2 id + 1 and
      // 2 id + 2 the start and end of sphere id's chord, so ties are taken in sphere order.
      ev.clear();
      for (int k = A.first[l]; k < A.first[l + 1]; ++k) {
        ev.push_back({A.shape[k].t0, 0});
        ev.push_back({A.shape[k].t1, 0});
      }
      for (int k = 0; k < nc; ++k) {
        ev.push_back({chords[k].t0, 2 * chords[k].id + 1});
        ev.push_back({chords[k].t1, 2 * chords[k].id + 2});
      }
      std::sort(ev.begin(), ev.end());
      int cover = 0;
      long long idsum = 0;
      bool in_shape = false;
      double open = 0.0;
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
        if (x.key == 0) {
          in_shape = !in_shape;
        } else if (x.key & 1) {
          if (cover++ == 0) open = x.t;
          idsum += (x.key - 1) / 2;
        } else {
          if (--cover == 0 && moments) uni.push_back({open, x.t});
          idsum -= (x.key - 1) / 2;
        }
      }
      // |S xor U| = |S| + |U| - 2 |S and U|; |S| is added per axis below.
      xor_len += lu - 2.0 * li;
      uni_len += lu;
      if (moments) accumulate_moments(uni, axis, A.pu[l], A.pv[l], area, m);
    }
    outs[task].xor_len = xor_len;
    outs[task].uni_len = uni_len;
    if (moments) outs[task].m = m;
  }
  Eval e;
  if (removal_cost) removal_cost->assign(spheres.size(), 0.0);
  for (int axis = 0; axis < 3; ++axis) {
    const Axis& A = axes_[axis];
    const double w = A.du * A.dv / 3.0;
    double xor_len = A.shape_total, uni_len = 0.0;
    Moments m;
    for (int b = 0; b < kBlocks; ++b) {
      const BlockOut& o = outs[axis * kBlocks + b];
      xor_len += o.xor_len;
      uni_len += o.uni_len;
      if (moments) m += o.m;
      if (removal_cost && !o.cost.empty())
        for (size_t k = 0; k < spheres.size(); ++k) (*removal_cost)[k] += o.cost[k] * w;
    }
    e.xor_volume += xor_len * w;
    e.union_volume += uni_len * w;
    if (moments) {
      m.m0 /= 3.0;
      m.m1 /= 3.0;
      m.m2 /= 3.0;
      e.union_moments += m;
    }
  }
  return e;
}

void RayCache::local(const Spheres& spheres, int i, double reach, Local& L, int max_lines,
                     int phase) const {
  const Eigen::Vector3d& c = spheres[i].center;
  // A large sphere keeps every stride-th row and column of each axis' line grid (the lines stay
  // evenly spread; each stands for stride^2 of them).
  double expected = 0.0;
  for (const Axis& A : axes_) expected += std::numbers::pi * reach * reach / (A.du * A.dv);
  const int stride =
      max_lines > 0 ? std::max(1, static_cast<int>(std::ceil(std::sqrt(expected / max_lines)))) : 1;
  L.scale = static_cast<double>(stride) * stride;
  const int off_a = stride > 1 ? phase % stride : 0;
  const int off_b = stride > 1 ? (phase / stride) % stride : 0;
  // The rows (axis, a) of lines within reach, in a fixed order; each thread builds a contiguous
  // run of rows into its own part, and the parts are joined in order, so the result does not
  // depend on the thread count.
  struct Row {
    int axis, a, b0, b1;
  };
  std::vector<Row> rows;
  // The other spheres near the neighbourhood, per axis in order of their centres along it (so
  // the chord starts and ends on a line come nearly sorted).
  std::vector<int> near[3], order[3];
  axis_orders(spheres, order);
  for (int axis = 0; axis < 3; ++axis) {
    const Axis& A = axes_[axis];
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (const int id : order[axis]) {
      const Sphere& s = spheres[id];
      if (id != i && std::abs(s.center[u] - c[u]) < s.radius + reach &&
          std::abs(s.center[v] - c[v]) < s.radius + reach &&
          std::abs(s.center[axis] - c[axis]) < s.radius + reach)
        near[axis].push_back(id);
    }
    const int i0 = std::max(0, static_cast<int>(std::floor((c[u] - reach - A.u0) / A.du)));
    const int i1 = std::min(A.nu - 1, static_cast<int>(std::floor((c[u] + reach - A.u0) / A.du)));
    const int j0 = std::max(0, static_cast<int>(std::floor((c[v] - reach - A.v0) / A.dv)));
    const int j1 = std::min(A.nv - 1, static_cast<int>(std::floor((c[v] + reach - A.v0) / A.dv)));
    if (j1 < j0) continue;
    for (int a = i0; a <= i1; ++a)
      if (a % stride == off_a) rows.push_back({axis, a, j0, j1});
  }
  const int nrows = static_cast<int>(rows.size());
  const int parts = std::max(1, std::min(threads_, nrows / 8));
  L.parts.resize(parts);
#pragma omp parallel for num_threads(parts) schedule(static, 1)
  for (int p = 0; p < parts; ++p) {
    Local::Part& P = L.parts[p];
    P.lines.clear();
    P.t.clear();
    P.w.clear();
    P.slope.clear();
    std::vector<double> bnd, st, en;  // shape boundaries, chord starts, chord ends in the window
    const int r0 = static_cast<int>(static_cast<std::int64_t>(nrows) * p / parts);
    const int r1 = static_cast<int>(static_cast<std::int64_t>(nrows) * (p + 1) / parts);
    std::vector<int> row_near;
    for (int r = r0; r < r1; ++r) {
      const int axis = rows[r].axis;
      const Axis& A = axes_[axis];
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      // The other spheres that can cross this row's lines (all lie in one grid cell in u).
      const double ua = A.u0 + rows[r].a * A.du, ub = ua + A.du;
      row_near.clear();
      for (int id : near[axis]) {
        const Sphere& s = spheres[id];
        if (s.center[u] + s.radius > ua && s.center[u] - s.radius < ub) row_near.push_back(id);
      }
      // Only the window [lo, hi] along the line matters: every trial chord lies in it, and a
      // chord's value is a difference of W, so W may start from zero at lo.
      const double lo = c[axis] - reach, hi = c[axis] + reach;
      for (int b = rows[r].b0; b <= rows[r].b1; ++b) {
        if (b % stride != off_b) continue;
        const int l = rows[r].a * A.nv + b;
        const double du = A.pu[l] - c[u], dv = A.pv[l] - c[v];
        if (du * du + dv * dv >= reach * reach) continue;
        bnd.clear();
        st.clear();
        en.clear();
        bool in_shape = false;
        for (int k = A.first[l]; k < A.first[l + 1]; ++k) {
          const double t0 = A.shape[k].t0, t1 = A.shape[k].t1;
          if (t1 <= lo || t0 >= hi) continue;
          if (t0 <= lo)
            in_shape = true;
          else
            bnd.push_back(t0);
          if (t1 < hi) bnd.push_back(t1);
        }
        int cover = 0;
        for (int id : row_near) {
          const Sphere& s = spheres[id];
          const double x = A.pu[l] - s.center[u], y = A.pv[l] - s.center[v];
          const double h2 = s.radius * s.radius - x * x - y * y;
          if (h2 <= 0) continue;
          const double hh = std::sqrt(h2);
          const double t0 = s.center[axis] - hh, t1 = s.center[axis] + hh;
          if (t1 <= lo || t0 >= hi) continue;
          if (t0 <= lo)
            ++cover;
          else
            st.push_back(t0);
          if (t1 < hi) en.push_back(t1);
        }
        sort_nearly_sorted(st);
        sort_nearly_sorted(en);
        const int first = static_cast<int>(P.t.size());
        double w = 0.0, prev = lo;
        double sl = cover > 0 ? 0.0 : (in_shape ? -1.0 : 1.0);
        bool zero = sl == 0.0;  // a line wholly covered by other spheres adds nothing: dropped
        P.t.push_back(lo);
        P.w.push_back(0.0);
        P.slope.push_back(sl);
        merge_events(bnd.data(), bnd.size(), st, en, false, [&](double t, int kind) {
          w += sl * (t - prev);
          prev = t;
          if (kind == 0)
            in_shape = !in_shape;
          else if (kind == 1)
            ++cover;
          else
            --cover;
          sl = cover > 0 ? 0.0 : (in_shape ? -1.0 : 1.0);
          zero = zero && sl == 0.0;
          P.t.push_back(t);
          P.w.push_back(w);
          P.slope.push_back(sl);
        });
        if (zero) {
          P.t.resize(first);
          P.w.resize(first);
          P.slope.resize(first);
          continue;
        }
        P.lines.push_back({axis, A.pu[l], A.pv[l], first, static_cast<int>(P.t.size())});
      }
    }
  }
}

double RayCache::local_value(const Local& L, const Sphere& s) const {
  double out = 0.0;
  local_values(L, &s, 1, &out);
  return out;
}

void RayCache::local_values(const Local& L, const Sphere* s, int n, double* out) const {
  // Lines outer, spheres inner: the neighbourhood is read once per chunk of spheres, and each
  // sphere's sum still runs over the lines in the same order as for a single sphere.
  constexpr int kChunk = 32;
  for (int k0 = 0; k0 < n; k0 += kChunk) {
    const int m = std::min(kChunk, n - k0);
    double total[kChunk][3] = {};
    double r2[kChunk];
    for (int k = 0; k < m; ++k) r2[k] = s[k0 + k].radius * s[k0 + k].radius;
    for (const Local::Part& P : L.parts) {
      // W(t) on a line: cumulative weight from the window's start (t below it only by round-off).
      auto W = [&P](const Local::Line& ln, double t) {
        const double* first = P.t.data() + ln.b0;
        const double* last = P.t.data() + ln.b1;
        const double* it = std::upper_bound(first, last, t);
        if (it == first) return P.w[ln.b0] + P.slope[ln.b0] * (t - *first);
        const int k = static_cast<int>(it - P.t.data()) - 1;
        return P.w[k] + P.slope[k] * (t - P.t[k]);
      };
      for (const Local::Line& ln : P.lines) {
        const int u = (ln.axis + 1) % 3, v = (ln.axis + 2) % 3;
        for (int k = 0; k < m; ++k) {
          const Sphere& sk = s[k0 + k];
          const double x = ln.pu - sk.center[u], y = ln.pv - sk.center[v];
          const double h2 = r2[k] - x * x - y * y;
          if (h2 <= 0) continue;
          const double hh = std::sqrt(h2);
          total[k][ln.axis] += W(ln, sk.center[ln.axis] + hh) - W(ln, sk.center[ln.axis] - hh);
        }
      }
    }
    for (int k = 0; k < m; ++k) {
      double o = 0.0;
      for (int axis = 0; axis < 3; ++axis)
        o += total[k][axis] * axes_[axis].du * axes_[axis].dv / 3.0;
      out[k0 + k] = o * L.scale;
    }
  }
}

}  // namespace clumpkit::detail
