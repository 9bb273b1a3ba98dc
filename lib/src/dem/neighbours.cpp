// Cell lists with a Verlet skin. Sphere pairs (i < j, different clumps) closer than
// r_i + r_j + skin, and sphere-triangle candidates closer than r + skin, are listed at a
// rebuild; the lists stay valid until a sphere (or wall vertex) has moved far enough to close
// the skin. Everything is built in a fixed order, so lists are identical for any thread count.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include <omp.h>

#include "dem/world_impl.hpp"

namespace clumpkit::dem {

namespace {

constexpr std::int64_t kBias = 1 << 20;

std::uint64_t cell_key(std::int64_t x, std::int64_t y, std::int64_t z) {
  return (static_cast<std::uint64_t>(x + kBias) << 42) |
         (static_cast<std::uint64_t>(y + kBias) << 21) | static_cast<std::uint64_t>(z + kBias);
}

std::int64_t cell_of(double v, double cell) {
  const double c = std::floor(v / cell);
  return static_cast<std::int64_t>(std::clamp(c, double(-kBias + 2), double(kBias - 2)));
}

// Sorts v by insertion, giving up (false, v then partly sorted) after `max_moves` moves.
template <class T>
bool insertion_sort(std::vector<T>& v, std::size_t max_moves) {
  std::size_t moves = 0;
  for (std::size_t k = 1; k < v.size(); ++k) {
    if (!(v[k] < v[k - 1])) continue;
    T x = v[k];
    std::size_t m = k;
    do {
      v[m] = v[m - 1];
      --m;
    } while (m > 0 && x < v[m - 1]);
    v[m] = x;
    moves += k - m;
    if (moves > max_moves) return false;
  }
  return true;
}

}  // namespace

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  // Voronoi regions of the vertices, edges and face, in barycentric terms.
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

void World::Impl::rebuild_neighbours() {
  const int ns = static_cast<int>(s_r.size());
  const double h = cell > 0.0 ? cell : 1.0;

  // Spheres sorted by cell, with their positions, radii and clumps copied in that order (the
  // candidates of one cell column are then contiguous in memory).
  // The bins start in the last rebuild's order when the sphere count is unchanged: few spheres
  // change cells between rebuilds, so an insertion sort is nearly linear. The sorted order is
  // that of (key, sphere), a total order, so it does not depend on where the sort started.
  std::vector<std::pair<std::uint64_t, int>>& bins = scratch_bins;
  const bool reuse = static_cast<int>(bins.size()) == ns;
  if (!reuse) {
    bins.resize(ns);
    for (int s = 0; s < ns; ++s) bins[s].second = s;
  }
  std::vector<std::array<std::int64_t, 3>> sc(ns);
#pragma omp parallel for num_threads(threads) schedule(static) if (ns >= kParallelMin)
  for (int s = 0; s < ns; ++s)
    sc[s] = {cell_of(s_pos[s].x(), h), cell_of(s_pos[s].y(), h), cell_of(s_pos[s].z(), h)};
  for (auto& [key, s] : bins) key = cell_key(sc[s][0], sc[s][1], sc[s][2]);
  if (!reuse || !insertion_sort(bins, 8 * static_cast<std::size_t>(ns)))
    std::sort(bins.begin(), bins.end());
  std::vector<std::uint64_t> keys(ns);
  std::vector<Eigen::Vector4d> sorted(ns);  // x, y, z, r
  std::vector<int> sorted_clump(ns);
  // Runs of one cell: [runs[k], runs[k + 1]) in the sorted bins.
  std::vector<int> runs;
  runs.reserve(ns / 2 + 2);
  for (int k = 0; k < ns; ++k) {
    const int s = bins[k].second;
    keys[k] = bins[k].first;
    sorted[k] << s_pos[s], s_r[s];
    sorted_clump[k] = s_clump[s];
    if (k == 0 || keys[k] != keys[k - 1]) runs.push_back(k);
  }
  const int nruns = static_cast<int>(runs.size());
  runs.push_back(ns);
  // Half shell: each pair of spheres is tested once, from the cell with the smaller key. The 13
  // neighbour cells with a larger key are the column (x, y, z+1) and the four columns
  // (x, y+1), (x+1, y−1 … y+1), each three cells z−1 … z+1; a column's three cells are
  // consecutive keys (z is the low field), so each is one binary search and one contiguous run
  // of the sorted bins, looked up once per occupied cell. Within the sphere's own cell only the
  // spheres after it in the sorted order are tested, and the own cell and (x, y, z+1) are one
  // contiguous run.
  auto column = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    const int lo = static_cast<int>(
        std::lower_bound(keys.begin(), keys.end(), cell_key(x, y, z - 1)) - keys.begin());
    const std::uint64_t last = cell_key(x, y, z + 1);
    int hi = lo;
    while (hi < ns && keys[hi] <= last) ++hi;
    return std::array<int, 2>{lo, hi};
  };

  // Pairs found, per thread, as (smaller, larger) sphere index; gathered below into the list
  // sorted by (i, j), which does not depend on which thread found what.
  const int nt = std::max(1, threads);
  std::vector<PerThread<std::array<int, 2>>>& found = scratch_found;
  found.resize(nt);
  for (auto& f : found) f.v.clear();
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16) if (ns >= kParallelMin)
  for (int r = 0; r < nruns; ++r) {
    auto& out = found[omp_get_thread_num()].v;
    const std::array<std::int64_t, 3>& c = sc[bins[runs[r]].second];
    const std::uint64_t above = cell_key(c[0], c[1], c[2] + 1);
    int own_hi = runs[r + 1];
    while (own_hi < ns && keys[own_hi] == above) ++own_hi;
    const std::array<std::array<int, 2>, 4> cols = {
        column(c[0], c[1] + 1, c[2]), column(c[0] + 1, c[1] - 1, c[2]),
        column(c[0] + 1, c[1], c[2]), column(c[0] + 1, c[1] + 1, c[2])};
    for (int k = runs[r]; k < runs[r + 1]; ++k) {
      const int i = bins[k].second;
      const Eigen::Vector4d pi = sorted[k];
      const int ci = sorted_clump[k];
      auto test = [&](int lo, int hi) {
        for (int m = lo; m < hi; ++m) {
          if (sorted_clump[m] == ci) continue;
          const double rr = pi[3] + sorted[m][3] + skin;
          if ((pi.head<3>() - sorted[m].head<3>()).squaredNorm() < rr * rr) {
            const int j = bins[m].second;
            out.push_back(i < j ? std::array<int, 2>{i, j} : std::array<int, 2>{j, i});
          }
        }
      };
      test(k + 1, own_hi);
      for (const auto& [lo, hi] : cols) test(lo, hi);
    }
  }
  // Counting sort by i, then each i's partners sorted.
  std::vector<int>& start = scratch_start;
  start.assign(ns + 1, 0);
  size_t npairs = 0;
  for (const auto& f : found) {
    npairs += f.v.size();
    for (const auto& p : f.v) ++start[p[0] + 1];
  }
  for (int i = 0; i < ns; ++i) start[i + 1] += start[i];
  std::vector<PairEntry> next(npairs);
  {
    std::vector<int>& fill = scratch_fill;
    fill.assign(start.begin(), start.end() - 1);
    for (const auto& f : found)
      for (const auto& p : f.v) next[fill[p[0]]++] = {p[0], p[1]};
  }
#pragma omp parallel for num_threads(threads) schedule(static) if (ns >= kParallelMin)
  for (int i = 0; i < ns; ++i)
    if (start[i + 1] - start[i] > 1)
      std::sort(next.begin() + start[i], next.begin() + start[i + 1],
                [](const PairEntry& a, const PairEntry& b) { return a.j < b.j; });
  // Carry histories over (both lists are sorted by (i, j)).
  std::vector<ContactHistory> next_hist(next.size());
  size_t a = 0;
  for (size_t k = 0; k < next.size(); ++k) {
    while (a < pairs.size() && pairs[a] < next[k]) ++a;
    if (a < pairs.size() && pairs[a] == next[k]) next_hist[k] = pair_hist[a];
  }
  pairs.swap(next);
  pair_hist.swap(next_hist);
  pair_live.clear();  // rebuilt from the carried histories at the next detection

  // Wall triangles binned into the cells their (grown) bounding boxes touch, in each wall's
  // frame at t = 0 (once: a wall moves rigidly). The bins only pre-select; the exact test below
  // is on the current vertices, so the candidates are those of a binning of the moved wall. The
  // boxes grow by a hair more than the reach, against rounding in the change of frame.
  const double grow = r_max + skin + 1e-9 * h;
  const int nw = static_cast<int>(walls.size());
  if (!tri_bins_valid) {
    tri_bins.assign(nw, {});
    for (int wi = 0; wi < nw; ++wi) {
      const WallData& wd = walls[wi];
      auto& bins_w = tri_bins[wi];
      for (size_t ti = 0; ti < wd.triangles.size(); ++ti) {
        const auto& t = wd.triangles[ti];
        const auto& v = wd.ref_vertices;
        Eigen::Vector3d lo = v[t[0]].cwiseMin(v[t[1]]).cwiseMin(v[t[2]]);
        Eigen::Vector3d hi = v[t[0]].cwiseMax(v[t[1]]).cwiseMax(v[t[2]]);
        lo.array() -= grow;
        hi.array() += grow;
        const std::int64_t x0 = cell_of(lo.x(), h), x1 = cell_of(hi.x(), h);
        const std::int64_t y0 = cell_of(lo.y(), h), y1 = cell_of(hi.y(), h);
        const std::int64_t z0 = cell_of(lo.z(), h), z1 = cell_of(hi.z(), h);
        for (std::int64_t x = x0; x <= x1; ++x)
          for (std::int64_t y = y0; y <= y1; ++y)
            for (std::int64_t z = z0; z <= z1; ++z)
              bins_w.push_back({cell_key(x, y, z), static_cast<int>(ti)});
      }
      std::sort(bins_w.begin(), bins_w.end());
    }
    tri_bins_valid = true;
  }
  std::vector<char> at_rest(nw);
  for (int wi = 0; wi < nw; ++wi) at_rest[wi] = walls[wi].state.pose.at_rest();
  std::vector<std::vector<std::array<int, 2>>>& cand = scratch_cand;
  cand.resize(ns);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16) if (ns >= kParallelMin)
  for (int r = 0; r < nruns; ++r) {
    for (int k = runs[r]; k < runs[r + 1]; ++k) cand[bins[k].second].clear();
    for (int wi = 0; wi < nw; ++wi) {
      const auto& bins_w = tri_bins[wi];
      if (bins_w.empty()) continue;
      const WallData& wd = walls[wi];
      auto lookup = [&](std::uint64_t key) {
        return std::lower_bound(bins_w.begin(), bins_w.end(), std::make_pair(key, -1));
      };
      // A wall at rest: one lookup for the cell (its frame is the world's).
      const auto rest_lo = at_rest[wi] ? lookup(keys[runs[r]]) : bins_w.end();
      // A moving wall: the spheres of one cell mostly fall in one cell of the wall's frame, so
      // the last look-up is kept.
      std::uint64_t last_key = 0;
      auto last_lo = bins_w.end();
      for (int k = runs[r]; k < runs[r + 1]; ++k) {
        const int s = bins[k].second;
        std::uint64_t key = keys[k];
        auto lo = rest_lo;
        if (!at_rest[wi]) {
          const Eigen::Vector3d x = wd.state.pose.unapply(s_pos[s]);
          key = cell_key(cell_of(x.x(), h), cell_of(x.y(), h), cell_of(x.z(), h));
          if (k == runs[r] || key != last_key) {
            last_key = key;
            last_lo = lookup(key);
          }
          lo = last_lo;
        }
        const double reach = s_r[s] + skin;
        for (auto it = lo; it != bins_w.end() && it->first == key; ++it) {
          if (beyond_plane(wd, it->second, s_pos[s], reach)) continue;
          const auto& t = wd.triangles[it->second];
          const Eigen::Vector3d c = closest_point_on_triangle(s_pos[s], wd.vertices[t[0]],
                                                              wd.vertices[t[1]], wd.vertices[t[2]]);
          if ((c - s_pos[s]).squaredNorm() < reach * reach) cand[s].push_back({wi, it->second});
        }
      }
    }
  }
  wall_cand.clear();
  wall_cand_start.assign(ns + 1, 0);
  for (int s = 0; s < ns; ++s) {
    wall_cand.insert(wall_cand.end(), cand[s].begin(), cand[s].end());
    wall_cand_start[s + 1] = static_cast<int>(wall_cand.size());
  }

  s_pos_build = s_pos;
  for (WallData& wd : walls) wd.vertices_build = wd.vertices;
  need_rebuild = false;
  refresh_wall_active();
}

bool World::Impl::pair_list_complete(double d1) {
  // The last rebuild's bins: (cell key, sphere) of every sphere where it was then, sorted.
  const int ns = static_cast<int>(s_r.size());
  const int nc = static_cast<int>(c_first.size());
  const std::vector<std::pair<std::uint64_t, int>>& bins = scratch_bins;
  // Displacements of other clumps than the current ones, or cells too small for the search
  // below: rebuild.
  if (static_cast<int>(c_disp2.size()) != nc || cell < 2.0 * r_max + skin || d1 > skin)
    return false;
  // A pair missing from the list was at least r_i + r_j + skin apart at the rebuild, so it
  // touches now only if its clumps moved more than the skin together: both more than
  // skin - d1 (neither moved more than d1), one of them more than half.
  auto listed = [&](int i, int j) {
    const PairEntry key{std::min(i, j), std::max(i, j)};
    const auto at = std::lower_bound(pairs.begin(), pairs.end(), key);
    return at != pairs.end() && *at == key;
  };
  auto touching = [&](int i, int j) {
    const double rr = s_r[i] + s_r[j];
    return (s_pos[i] - s_pos[j]).squaredNorm() < rr * rr;
  };
  // The clumps that moved that far, and among them those that moved more than half the skin.
  // Past a quarter of the spheres among the latter, a search costs about what a rebuild does.
  const double lo = std::max(0.0, skin - d1), half2 = 0.25 * skin * skin;
  std::vector<std::pair<int, double>>& moved = scratch_moved;  // clump, displacement (m)
  std::vector<int>& fast = scratch_fast;                       // indices into moved
  moved.clear();
  fast.clear();
  int fast_spheres = 0;
  for (int c = 0; c < nc; ++c)
    if (c_disp2[c] > lo * lo) {
      if (c_disp2[c] > half2) {
        fast.push_back(static_cast<int>(moved.size()));
        fast_spheres += sphere_end(c) - c_first[c];
      }
      moved.push_back({c, std::sqrt(c_disp2[c])});
    }
  if (fast_spheres > ns / 4 + 8) return false;
  // Usually few clumps moved that far: each fast one's sphere pairs with the others are tested
  // directly, where their bounding spheres overlap.
  if (fast.size() * moved.size() <= 4 * static_cast<size_t>(ns)) {
    for (int fa : fast) {
      const auto [ca, da] = moved[fa];
      for (const auto& [cb, db] : moved) {
        if (cb == ca || da + db <= skin) continue;
        // Clumps farther apart than their bounding spheres reach cannot touch (with a hair
        // for rounding).
        const double reach =
            (types[c_type[ca]].bound_radius + types[c_type[cb]].bound_radius) * (1.0 + 1e-9);
        if ((c_x[ca] - c_x[cb]).squaredNorm() >= reach * reach) continue;
        for (int i = c_first[ca]; i < sphere_end(ca); ++i)
          for (int j = c_first[cb]; j < sphere_end(cb); ++j)
            if (touching(i, j) && !listed(i, j)) return false;
      }
    }
    return true;
  }
  // Otherwise the fast clumps' spheres are searched against all, in the bins; without bins of
  // the current spheres (a checkpoint was loaded since the last rebuild), rebuild.
  if (static_cast<int>(bins.size()) != ns) return false;
  const double h = cell;
  for (int c = 0; c < nc; ++c) {
    if (c_disp2[c] <= half2) continue;
    const double dc = std::sqrt(c_disp2[c]);
    for (int i = c_first[c]; i < sphere_end(c); ++i) {
      // A sphere j touching i now was within r_i + r_j + d1 <= 2 r_max + skin = one cell of
      // where i is now when the bins were made (it moved at most d1 <= skin since): the 27
      // cells around i's current cell hold it.
      const Eigen::Vector3d& p = s_pos[i];
      const std::int64_t x = cell_of(p.x(), h), y = cell_of(p.y(), h), z = cell_of(p.z(), h);
      for (std::int64_t dx = -1; dx <= 1; ++dx)
        for (std::int64_t dy = -1; dy <= 1; ++dy) {
          const std::uint64_t last = cell_key(x + dx, y + dy, z + 1);
          for (auto it = std::lower_bound(bins.begin(), bins.end(),
                                          std::make_pair(cell_key(x + dx, y + dy, z - 1), -1));
               it != bins.end() && it->first <= last; ++it) {
            const int j = it->second;
            const int cj = s_clump[j];
            if (cj == c || dc + std::sqrt(c_disp2[cj]) <= skin) continue;
            if (touching(i, j) && !listed(i, j)) return false;
          }
        }
    }
  }
  return true;
}

void World::Impl::refresh_wall_active() {
  const int ns = static_cast<int>(s_r.size());
  wall_active.clear();
  wall_row.assign(ns, -1);
  for (int s = 0; s < ns; ++s) {
    const bool held = wall_held[s] != 0;
    // The rows move: every count is rewritten by the detection that follows.
    wall_contact_n[s] = 0;
    if (held || wall_cand_start[s] != wall_cand_start[s + 1]) {
      wall_row[s] = static_cast<int>(wall_active.size());
      wall_active.push_back(s);
    }
  }
  wall_contacts.resize(wall_active.size());
  wall_active_dirty = false;
}

}  // namespace clumpkit::dem
