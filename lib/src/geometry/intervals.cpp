#include "clumpkit/geometry/intervals.hpp"

#include <algorithm>

namespace clumpkit {

void merge_intervals(IntervalList& list) {
  if (list.size() < 2) return;
  std::sort(list.begin(), list.end(), [](const Interval& a, const Interval& b) {
    return a.t0 < b.t0 || (a.t0 == b.t0 && a.t1 < b.t1);
  });
  size_t w = 0;
  for (size_t i = 1; i < list.size(); ++i) {
    if (list[i].t0 <= list[w].t1) {
      list[w].t1 = std::max(list[w].t1, list[i].t1);
    } else {
      list[++w] = list[i];
    }
  }
  list.resize(w + 1);
}

namespace {
// Sweep over the boundary events of both lists; `keep(in_a, in_b)` says which regions to output.
template <class Keep>
IntervalList combine(const IntervalList& a, const IntervalList& b, Keep keep) {
  IntervalList out;
  size_t i = 0, j = 0;
  bool in_a = false, in_b = false;
  double start = 0.0;
  bool open = false;
  while (i < 2 * a.size() || j < 2 * b.size()) {
    const double ta = i < 2 * a.size() ? (i % 2 ? a[i / 2].t1 : a[i / 2].t0) : 1e300;
    const double tb = j < 2 * b.size() ? (j % 2 ? b[j / 2].t1 : b[j / 2].t0) : 1e300;
    const double t = std::min(ta, tb);
    if (ta == t) {
      in_a = !in_a;
      ++i;
    }
    if (tb == t) {
      in_b = !in_b;
      ++j;
    }
    const bool now = keep(in_a, in_b);
    if (now && !open) {
      start = t;
      open = true;
    } else if (!now && open) {
      if (t > start) out.push_back({start, t});
      open = false;
    }
  }
  return out;
}
}  // namespace

IntervalList xor_intervals(const IntervalList& a, const IntervalList& b) {
  return combine(a, b, [](bool x, bool y) { return x != y; });
}

IntervalList intersect_intervals(const IntervalList& a, const IntervalList& b) {
  return combine(a, b, [](bool x, bool y) { return x && y; });
}

double total_length(const IntervalList& list) {
  double s = 0.0;
  for (const Interval& iv : list) s += iv.t1 - iv.t0;
  return s;
}

}  // namespace clumpkit
