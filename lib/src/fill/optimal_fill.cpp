// The optimiser. Stages, each a short function below:
//   seed      lazy-greedy maximum coverage: spheres of the largest admissible radius where they
//             cover the most still-uncovered inside voxels (submodular, so lazy evaluation is
//             exact);
//   refine    joint descent on all centres and radii against the symmetric difference sampled on a
//             fixed ray set; the gradient comes from each sphere's exposed surface (area inside the
//             shape pulls the surface out, area outside pushes it in), steps are accepted only if
//             the sampled objective falls (backtracking);
//   swap      remove the sphere whose loss costs least, re-seed one where coverage gains most,
//             refine, keep if better;
//   target    (error-target mode) grow until the target holds, then drop spheres while it holds.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <queue>

#include <fmt/format.h>

#include "clumpkit/core/error.hpp"
#include "clumpkit/fill/fill_problem.hpp"
#include "fill_context.hpp"

namespace clumpkit {

namespace {

using detail::FillContext;

class Optimiser {
 public:
  Optimiser(const FillShape& shape, const FillOptions& o)
      : ctx_(shape, o), o_(o), dirs_(detail::fibonacci_sphere(128)) {
    const auto& g = ctx_.grid;
    double rmax = 0.0;
    std::vector<std::int64_t> all;
    for (std::int64_t i = 0; i < g.size(); ++i) {
      if (!g.inside[i]) continue;
      const double rho = ctx_.tolerance - g.sdf[i];
      rmax = std::max(rmax, rho);
      if (rho >= o.min_radius && rho > 0.5 * g.h) all.push_back(i);
    }
    if (all.empty())
      throw InputError(shape.where, "--min-radius",
                       fmt::format("{:.4g} mm is larger than the largest sphere that fits in the "
                                   "shape ({:.4g} mm with the tolerance)",
                                   o.min_radius * 1e3, rmax * 1e3));
    const size_t stride = std::max<size_t>(1, all.size() / 60000 + 1);
    for (size_t k = 0; k < all.size(); k += stride) cand_.push_back(all[k]);
    std::vector<std::int64_t> in;
    for (std::int64_t i = 0; i < g.size(); ++i)
      if (g.inside[i]) in.push_back(i);
    const size_t stride_in = std::max<size_t>(1, in.size() / 40000 + 1);
    for (size_t k = 0; k < in.size(); k += stride_in) inside_pts_.push_back(voxel_center(in[k]));
    threads_ = o.threads > 0 ? o.threads : omp_get_max_threads();
    step_ = 0.01 * ctx_.size;
  }

  FillResult run() {
    t0_ = std::chrono::steady_clock::now();
    Spheres s;
    FillResult res;
    res.tolerance = ctx_.tolerance;
    if (o_.spheres > 0 && o_.max_error <= 0) {
      budget_mode(s, o_.spheres);
    } else {
      target_mode(s, o_.spheres > 0 ? o_.spheres : o_.max_spheres);
    }
    ctx_.enforce_containment(s);
    const auto err = ctx_.errors(s);
    res.spheres = s;
    res.error = err.metric;
    res.target_reached = o_.max_error <= 0 || err.metric <= o_.max_error;
    res.report = {{"algorithm",
                   "lazy-greedy coverage seeding, joint centre/radius descent on the "
                   "ray-sampled symmetric difference, swap moves, pruning"},
                  {"grid_cell", ctx_.grid.h},
                  {"candidates", cand_.size()},
                  {"objective_evaluations", evaluations_},
                  {"descent_iterations", iterations_},
                  {"symmetric_difference", err.symmetric_difference},
                  {"seconds", seconds()},
                  {"history", history_}};
    return res;
  }

 private:
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
  }
  // One line of the report's history, stamped with the time since the start (s).
  void note(nlohmann::json entry) {
    entry["seconds"] = seconds();
    history_.push_back(std::move(entry));
  }

  double objective(const Spheres& s) {
    ++evaluations_;
    return ctx_.objective(s);
  }

  // ---- seeding -------------------------------------------------------------------------------
  Eigen::Vector3d voxel_center(std::int64_t v) const {
    const auto& g = ctx_.grid;
    return g.center(static_cast<int>(v % g.n.x()), static_cast<int>((v / g.n.x()) % g.n.y()),
                    static_cast<int>(v / (static_cast<std::int64_t>(g.n.x()) * g.n.y())));
  }

  // Lloyd iterations (a centroidal Voronoi tessellation of the inside volume): every centre moves
  // to the centroid of the inside points nearest to it, then takes the largest admissible
  // radius. Spreads the spheres evenly, which the largest-first greedy does not.
  void lloyd(Spheres& s, int iters) const {
    const int n = static_cast<int>(s.size());
    if (n == 0) return;
    const int m = static_cast<int>(inside_pts_.size());
    std::vector<int> owner(m);
    for (int it = 0; it < iters; ++it) {
#pragma omp parallel for num_threads(threads_) schedule(static)
      for (int k = 0; k < m; ++k) {
        double best = std::numeric_limits<double>::infinity();
        int arg = 0;
        for (int i = 0; i < n; ++i) {
          const double d = (inside_pts_[k] - s[i].center).squaredNorm();
          if (d < best) {
            best = d;
            arg = i;
          }
        }
        owner[k] = arg;
      }
      std::vector<Eigen::Vector3d> sum(n, Eigen::Vector3d::Zero());
      std::vector<int> cnt(n, 0);
      for (int k = 0; k < m; ++k) {
        sum[owner[k]] += inside_pts_[k];
        ++cnt[owner[k]];
      }
      for (int i = 0; i < n; ++i)
        if (cnt[i] > 0) s[i].center = sum[i] / cnt[i];
    }
    const double rmin = std::max(o_.min_radius, 1e-6 * ctx_.size);
    for (Sphere& x : s) {
      x.radius = ctx_.max_radius(x.center);
      if (x.radius < rmin) {  // a centroid outside a non-convex shape: back to the nearest point
        double best = std::numeric_limits<double>::infinity();
        for (const auto& p : inside_pts_)
          if ((p - x.center).squaredNorm() < best && ctx_.max_radius(p) >= rmin) {
            best = (p - x.center).squaredNorm();
            x.center = p;
          }
        x.radius = std::max(rmin, ctx_.max_radius(x.center));
      }
    }
  }

  // Clears `open` (1: inside voxel not yet covered) in the ball.
  void mark(std::vector<std::uint8_t>& open, const Sphere& s) const {
    const auto& g = ctx_.grid;
    const Eigen::Vector3d q = (s.center - g.origin) / g.h;
    const int reach = static_cast<int>(std::ceil(s.radius / g.h)) + 1;
    const int ci = static_cast<int>(std::lround(q.x())), cj = static_cast<int>(std::lround(q.y())),
              ck = static_cast<int>(std::lround(q.z()));
    const double r2 = s.radius * s.radius;
    for (int k = std::max(0, ck - reach); k <= std::min(g.n.z() - 1, ck + reach); ++k)
      for (int j = std::max(0, cj - reach); j <= std::min(g.n.y() - 1, cj + reach); ++j) {
        // The row's chord through the ball, widened by a voxel; the exact test decides.
        const Eigen::Vector3d p = g.center(ci, j, k) - s.center;
        const double rest = r2 - p.y() * p.y() - p.z() * p.z();
        if (rest < 0) continue;
        const int half = static_cast<int>(std::sqrt(rest) / g.h) + 2;
        const int x0 = static_cast<int>(std::floor(q.x())) - half;
        const int x1 = static_cast<int>(std::ceil(q.x())) + half;
        for (int i = std::max(0, x0); i <= std::min(g.n.x() - 1, x1); ++i)
          if ((g.center(i, j, k) - s.center).squaredNorm() <= r2) open[g.index(i, j, k)] = 0;
      }
  }

  // Uncovered inside volume (in voxels) within the ball; sub-sampled for large balls (every s-th
  // voxel of each axis, offsets from the centre voxel that are multiples of s).
  double gain(const std::vector<std::uint8_t>& open, std::int64_t v, double r) const {
    const auto& g = ctx_.grid;
    const int ci = static_cast<int>(v % g.n.x()), cj = static_cast<int>((v / g.n.x()) % g.n.y()),
              ck = static_cast<int>(v / (static_cast<std::int64_t>(g.n.x()) * g.n.y()));
    const int s = std::max(1, static_cast<int>(r / (5.0 * g.h)));
    const int reach = static_cast<int>(r / g.h) / s * s;
    const double r2 = (r / g.h) * (r / g.h);
    std::int64_t count = 0;
    for (int dk = -reach; dk <= reach; dk += s) {
      const int k = ck + dk;
      if (k < 0 || k >= g.n.z()) continue;
      for (int dj = -reach; dj <= reach; dj += s) {
        const int j = cj + dj;
        if (j < 0 || j >= g.n.y()) continue;
        // The offsets di with di^2 + dj^2 + dk^2 <= r2 (the square root's guess made exact).
        const int q = dj * dj + dk * dk;
        if (q > r2) continue;
        int dm = static_cast<int>(std::sqrt(r2 - q));
        while ((dm + 1) * (dm + 1) + q <= r2) ++dm;
        while (dm * dm + q > r2) --dm;
        int lo = std::max({-dm, -reach, -ci});
        const int hi = std::min({dm, reach, g.n.x() - 1 - ci});
        lo = lo >= 0 ? (lo + s - 1) / s * s : -(-lo / s * s);  // up to a multiple of s
        const std::uint8_t* row = open.data() + g.index(ci, j, k);
        for (int di = lo; di <= hi; di += s) count += row[di];
      }
    }
    return static_cast<double>(count) * s * s * s;
  }

  // Adds up to `count` spheres by lazy-greedy maximum coverage, radii capped at `cap`. Returns
  // how many were added.
  int seed(Spheres& spheres, int count,
           double cap = std::numeric_limits<double>::infinity()) const {
    const auto& g = ctx_.grid;
    std::vector<std::uint8_t> open = g.inside;  // inside voxels not yet covered
    for (const Sphere& s : spheres) mark(open, s);
    struct Item {
      double bound;
      int round;
      std::int64_t cand;
      bool operator<(const Item& o) const {
        return bound < o.bound || (bound == o.bound && cand > o.cand);
      }
    };
    std::priority_queue<Item> pq;
    for (std::int64_t c = 0; c < static_cast<std::int64_t>(cand_.size()); ++c) {
      const double rho = std::min(ctx_.tolerance - g.sdf[cand_[c]], cap) / g.h;
      pq.push({4.0 / 3.0 * std::numbers::pi * rho * rho * rho + 8.0, -1, c});
    }
    int added = 0;
    std::vector<Item> batch;
    Spheres placed;  // the sphere placed in each round
    for (int round = 0; round < count && !pq.empty(); ++round) {
      while (!pq.empty()) {
        Item top = pq.top();
        pq.pop();
        if (top.round != round) {
          // Stale bounds are refreshed a batch at a time, in parallel: the next stale items in
          // queue order (a fixed number, so the result does not depend on the thread count). A
          // bound computed in an earlier round is still exact if no sphere placed since then
          // reaches the candidate's ball.
          batch.clear();
          auto take = [&](Item it) {
            if (it.round >= 0) {
              const Eigen::Vector3d c = voxel_center(cand_[it.cand]);
              const double rho = std::min(ctx_.tolerance - g.sdf[cand_[it.cand]], cap);
              bool touched = false;
              for (int k = it.round; k < round && !touched; ++k)
                touched = (placed[k].center - c).norm() < placed[k].radius + rho + 2.0 * g.h;
              if (!touched) {
                it.round = round;
                pq.push(it);
                return;
              }
            }
            batch.push_back(it);
          };
          take(top);
          while (batch.size() < 32 && !pq.empty() && pq.top().round != round) {
            const Item it = pq.top();
            pq.pop();
            take(it);
          }
          const int nb = static_cast<int>(batch.size());
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 1)
          for (int k = 0; k < nb; ++k) {
            const double rho = std::min(ctx_.tolerance - g.sdf[cand_[batch[k].cand]], cap);
            batch[k].bound = gain(open, cand_[batch[k].cand], rho);
            batch[k].round = round;
          }
          for (const Item& it : batch) pq.push(it);
          continue;
        }
        if (top.bound < 0.5) return added;  // nothing left to cover
        Sphere s;
        s.center = g.center(0, 0, 0);
        const std::int64_t v = cand_[top.cand];
        s.center +=
            g.h * Eigen::Vector3d(
                      static_cast<double>(v % g.n.x()),
                      static_cast<double>((v / g.n.x()) % g.n.y()),
                      static_cast<double>(v / (static_cast<std::int64_t>(g.n.x()) * g.n.y())));
        s.radius = std::min(ctx_.max_radius(s.center), cap);
        if (s.radius < std::max(o_.min_radius, 1e-6 * ctx_.size)) continue;  // drop candidate
        spheres.push_back(s);
        placed.push_back(s);
        mark(open, s);
        ++added;
        break;
      }
    }
    return added;
  }

  // ---- descent -------------------------------------------------------------------------------
  struct Grad {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    double r = 0.0;
  };
  std::vector<Grad> gradient(const Spheres& s) const {
    const int n = static_cast<int>(s.size());
    std::vector<Grad> g(n);
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 1)
    for (int i = 0; i < n; ++i) {
      std::vector<int> nb;
      for (int j = 0; j < n; ++j)
        if (j != i && (s[i].center - s[j].center).norm() < s[i].radius + s[j].radius)
          nb.push_back(j);
      const double da =
          4.0 * std::numbers::pi * s[i].radius * s[i].radius / static_cast<double>(dirs_.size());
      for (const Eigen::Vector3d& u : dirs_) {
        const Eigen::Vector3d p = s[i].center + s[i].radius * u;
        bool hidden = false;
        for (int j : nb)
          if ((p - s[j].center).squaredNorm() < s[j].radius * s[j].radius) {
            hidden = true;
            break;
          }
        if (hidden) continue;
        const double sign = ctx_.inside(p) ? -1.0 : 1.0;
        g[i].c += sign * da * u;
        g[i].r += sign * da;
      }
    }
    return g;
  }

  // Moves every sphere against the gradient by `step` (a length), then projects onto the
  // constraints min_radius <= r <= tolerance - distance(c).
  Spheres move(const Spheres& s, const std::vector<Grad>& g, double step) const {
    Spheres out = s;
    const int n = static_cast<int>(s.size());
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 1)
    for (int i = 0; i < n; ++i) {
      const double r = s[i].radius, norm = std::numbers::pi * r * r;
      const double rho = ctx_.max_radius(s[i].center);
      Eigen::Vector3d dc = g[i].c;
      if (r >= rho - 1e-6 * ctx_.size && g[i].r < 0)  // radius held by the constraint
        dc -= g[i].r * ctx_.distance_gradient(s[i].center);
      Eigen::Vector3d c = s[i].center - step * dc / norm;
      double nr = r - step * g[i].r / norm;
      const double rho_new = ctx_.max_radius(c);
      if (rho_new < std::max(o_.min_radius, 1e-6 * ctx_.size)) {
        c = s[i].center;
        nr = std::min(r, rho);
      } else {
        nr = std::clamp(nr, std::max(o_.min_radius, 1e-6 * ctx_.size), rho_new);
      }
      out[i].center = c;
      out[i].radius = nr;
    }
    return out;
  }

  double refine(Spheres& s, int iters) {
    double f = objective(s);
    if (s.empty()) return f;
    int stalls = 0;
    for (int it = 0; it < iters; ++it) {
      ++iterations_;
      const auto g = gradient(s);
      bool accepted = false;
      for (int tries = 0; tries < 5; ++tries) {
        Spheres t = move(s, g, step_);
        const double ft = objective(t);
        if (ft < f) {
          stalls = (f - ft) < 1e-4 * f ? stalls + 1 : 0;
          s = std::move(t);
          f = ft;
          step_ = std::min(step_ * 1.3, 0.1 * ctx_.size);
          accepted = true;
          break;
        }
        step_ *= 0.35;
      }
      if (!accepted) {
        step_ = std::max(step_, 1e-4 * ctx_.size);
        if (++stalls > 3) break;
      }
      if (stalls > 4) break;
    }
    return f;
  }

  // ---- per-sphere polish ----------------------------------------------------------------------
  // Pattern search, one sphere at a time, each with its own step: the centre along the three
  // axes and along its own descent direction (radius kept, or grown to the largest admissible),
  // the radius alone up and down. Moves are scored incrementally (only the rays the sphere
  // crosses before or after) and taken when the sampled symmetric difference falls.
  //
  // All but the last `exact_sweeps` sweeps score a large sphere on an evenly spread subset of its
  // rays (at most kPolishLines lines; a different subset each sweep), so a sweep costs about the
  // same whatever the radii; the last sweeps use every ray.
  static constexpr int kPolishLines = 2000;
  double polish(Spheres& s, int sweeps, int exact_sweeps) {
    const int n = static_cast<int>(s.size());
    if (n == 0) return objective(s);
    const double vs = ctx_.cache->shape_volume();
    const double rmin = std::max(o_.min_radius, 1e-6 * ctx_.size);
    std::vector<double> delta(n);
    for (int i = 0; i < n; ++i) delta[i] = 0.1 * s[i].radius;
    detail::RayCache::Local L;
    Spheres trials;
    std::vector<double> values;
    for (int sweep = 0; sweep < sweeps; ++sweep) {
      ++iterations_;
      const auto g = gradient(s);
      bool active = false;
      const int max_lines = sweep >= sweeps - exact_sweeps ? 0 : kPolishLines;
      for (int i = 0; i < n; ++i) {
        if (delta[i] < 2e-3 * s[i].radius) continue;
        active = true;
        const Sphere cur = s[i];
        const double rho_cur = ctx_.max_radius(cur.center);
        // Every trial sphere lies within ball(c, r + 2 delta) (radii grow by at most delta).
        ctx_.cache->local(s, i, cur.radius + 2.0 * delta[i] + 1e-9 * ctx_.size, L, max_lines,
                          sweep * 7 + i);
        ++evaluations_;
        Eigen::Vector3d dc = g[i].c;
        if (cur.radius >= rho_cur - 1e-6 * ctx_.size && g[i].r < 0)
          dc -= g[i].r * ctx_.distance_gradient(cur.center);
        // Trials are cheap here: the descent direction at three step lengths, the six axis
        // directions, and the radius alone. They are scored in parallel and compared in order.
        trials.assign(1, cur);  // trials[0]: the current sphere, the base value
        auto shift = [&](const Eigen::Vector3d& u, double len) {
          Sphere t;
          t.center = cur.center + len * u;
          const double rho = ctx_.max_radius(t.center);
          if (rho < rmin) return;
          t.radius = std::max(rmin, std::min(cur.radius, rho));
          trials.push_back(t);
          const double grown = std::min(rho, cur.radius + len);
          if (grown > t.radius * (1 + 1e-9)) {
            t.radius = grown;
            trials.push_back(t);
          }
        };
        if (dc.norm() > 0)
          for (const double k : {1.0, 0.5, 0.25}) shift(-dc.normalized(), k * delta[i]);
        for (int a = 0; a < 3; ++a)
          for (const double sg : {1.0, -1.0}) shift(sg * Eigen::Vector3d::Unit(a), delta[i]);
        for (const double dr : {delta[i], -delta[i], 0.3 * delta[i], -0.3 * delta[i]}) {
          Sphere t = cur;
          t.radius = std::clamp(cur.radius + dr, rmin, std::max(rmin, rho_cur));
          if (t.radius != cur.radius) trials.push_back(t);
        }
        const int nt = static_cast<int>(trials.size());
        values.resize(nt);
        // Scored in contiguous runs, one per thread (each run reads the neighbourhood once).
        const int runs = std::min(threads_, nt);
#pragma omp parallel for num_threads(runs) schedule(static, 1)
        for (int p = 0; p < runs; ++p) {
          const int k0 = nt * p / runs, k1 = nt * (p + 1) / runs;
          ctx_.cache->local_values(L, trials.data() + k0, k1 - k0, values.data() + k0);
        }
        const double base = values[0];
        double best_d = -1e-9 * vs;
        Sphere best = cur;
        for (int k = 1; k < nt; ++k)
          if (values[k] - base < best_d) {
            best_d = values[k] - base;
            best = trials[k];
          }
        if (best_d < -1e-9 * vs) {
          s[i] = best;
          delta[i] = std::min(1.5 * delta[i], 0.3 * s[i].radius);
        } else {
          delta[i] *= 0.5;
        }
      }
      if (!active) break;
    }
    return objective(s);  // on every ray (the sweeps may have scored subsets)
  }

  // ---- swaps and pruning ---------------------------------------------------------------------
  // Objective increase when each sphere is removed.
  std::vector<double> contributions(const Spheres& s) {
    std::vector<double> d;
    ++evaluations_;
    ctx_.objective(s, &d);
    return d;
  }

  void budget_mode(Spheres& s, int n) {
    // Multi-start: the plain coverage greedy opens with the largest sphere, which can trap the
    // descent (a flat pill); starts whose radii are capped near the equal-volume radius of n
    // spheres spread the spheres out. The best start after a short descent goes on.
    const double r_eq = std::cbrt(3.0 * ctx_.cache->shape_volume() / (4.0 * std::numbers::pi * n));
    const double inf = std::numeric_limits<double>::infinity();
    // Starts: the plain, 1.25 r_eq- and r_eq-capped seedings (independent and serial inside, so
    // run side by side), then the r_eq-capped one moved by Lloyd iterations.
    const double caps[3] = {inf, 1.25 * r_eq, r_eq};
    Spheres seeded[3];
#pragma omp parallel for num_threads(std::min(threads_, 3)) schedule(dynamic, 1)
    for (int k = 0; k < 3; ++k) seed(seeded[k], n, caps[k]);
    std::vector<std::pair<double, Spheres>> starts;
    for (int k = 0; k < 4; ++k) {
      const bool with_lloyd = k == 3;
      const double cap = caps[std::min(k, 2)];
      Spheres t = seeded[std::min(k, 2)];
      if (with_lloyd) lloyd(t, 25);
      step_ = 0.01 * ctx_.size;
      const double ft = refine(t, 15);
      note({{"stage", "start"},
            {"radius_cap", std::isinf(cap) ? -1.0 : cap},
            {"lloyd", with_lloyd},
            {"spheres", t.size()},
            {"objective", ft}});
      starts.emplace_back(ft, std::move(t));
    }
    // The two best starts are descended and polished in full (the second only if its descent
    // ends within twice the first's objective: polish rarely gains more); the better goes on.
    std::stable_sort(starts.begin(), starts.end(),
                     [](const auto& x, const auto& y) { return x.first < y.first; });
    double f = inf, first_descent = inf;
    for (size_t k = 0; k < std::min<size_t>(2, starts.size()); ++k) {
      Spheres t = std::move(starts[k].second);
      step_ = 0.01 * ctx_.size;
      const double fd = refine(t, 30);
      if (k == 0) first_descent = fd;
      if (k > 0 && fd > 2.0 * first_descent) {
        note({{"stage", "descent"}, {"spheres", t.size()}, {"objective", fd}});
        break;
      }
      const double ft = polish(t, 12, 0);
      note({{"stage", "descent+polish"}, {"spheres", t.size()}, {"objective", ft}});
      if (ft < f) {
        f = ft;
        s = std::move(t);
      }
    }
    // Swaps: remove the least useful sphere, re-seed one where coverage gains most.
    const int rounds = std::clamp(120 / std::max(1, n), 2, 8);
    for (int round = 0; round < rounds && !s.empty(); ++round) {
      const auto d = contributions(s);
      const size_t worst = static_cast<size_t>(std::min_element(d.begin(), d.end()) - d.begin());
      Spheres t = s;
      t.erase(t.begin() + static_cast<std::ptrdiff_t>(worst));
      if (seed(t, 1) == 0) break;
      step_ = 0.01 * ctx_.size;
      refine(t, 12);
      const double ft = polish(t, 8, 0);
      if (ft < f - 1e-6 * f) {
        s = std::move(t);
        f = ft;
        note({{"stage", "swap"}, {"spheres", s.size()}, {"objective", f}});
      } else {
        break;
      }
    }
    // A sphere count below the budget is allowed only if the shape is fully covered already.
    if (static_cast<int>(s.size()) < n) {
      seed(s, n - static_cast<int>(s.size()));
      refine(s, 20);
    }
    f = polish(s, 25, 2);
    note({{"stage", "polish"}, {"spheres", s.size()}, {"objective", f}});
  }

  void target_mode(Spheres& s, int cap) {
    int add = 1;
    double err = 1.0;
    while (static_cast<int>(s.size()) < cap) {
      const int got = seed(s, std::min(add, cap - static_cast<int>(s.size())));
      refine(s, 12);
      err = ctx_.errors(s).metric;
      note({{"stage", "grow"}, {"spheres", s.size()}, {"error", err}});
      if (err <= o_.max_error || got == 0) break;
      add = std::max(1, static_cast<int>(s.size()) / 12);
    }
    if (err > o_.max_error) {
      refine(s, 40);
      return;
    }
    prune(s, 8, 0, "prune");
    // Search below: full budget fills (seeding starts, descent, swaps, kicks) at fewer spheres,
    // bisecting between half the pruned count (assumed too few) and the pruned count.
    int hi = static_cast<int>(s.size()), lo = hi / 2 - 1;
    while (hi - lo > 1) {
      const int mid = (lo + hi) / 2;
      if (mid < 1) break;
      Spheres t;
      budget_mode(t, mid);
      const double e = ctx_.errors(t).metric;
      note({{"stage", "budget_search"}, {"spheres", t.size()}, {"error", e}});
      if (e <= o_.max_error) {
        hi = static_cast<int>(t.size());
        s = std::move(t);
      } else {
        lo = mid;
      }
    }
    // Below the search's count, warm-started: the best fill less its least useful sphere,
    // descended and polished, can still meet the target where a fill from scratch at that count
    // did not (each budget is its own local optimum).
    prune(s, 20, 12, "warm_prune");
  }

  // Drops the least useful sphere while the target still holds: each trial is descended
  // (`iters` steps) and, with `polish_sweeps` > 0, polished from a fresh step.
  void prune(Spheres& s, int iters, int polish_sweeps, const char* stage) {
    for (int guard = 0; guard < 1000 && s.size() > 1; ++guard) {
      const auto d = contributions(s);
      const size_t worst = static_cast<size_t>(std::min_element(d.begin(), d.end()) - d.begin());
      Spheres t = s;
      t.erase(t.begin() + static_cast<std::ptrdiff_t>(worst));
      if (polish_sweeps > 0) step_ = 0.01 * ctx_.size;
      refine(t, iters);
      if (polish_sweeps > 0) polish(t, polish_sweeps, 2);
      const double e = ctx_.errors(t).metric;
      if (e > o_.max_error) break;
      s = std::move(t);
      note({{"stage", stage}, {"spheres", s.size()}, {"error", e}});
    }
  }

  FillContext ctx_;
  FillOptions o_;
  std::vector<Eigen::Vector3d> dirs_;
  std::vector<std::int64_t> cand_;
  std::vector<Eigen::Vector3d> inside_pts_;  // inside voxel centres (sub-sampled), for Lloyd
  int threads_ = 1;
  double step_ = 0.0;
  std::int64_t evaluations_ = 0, iterations_ = 0;
  nlohmann::json history_ = nlohmann::json::array();
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

}  // namespace

FillResult optimal_fill(const FillShape& shape, const FillOptions& options) {
  Optimiser opt(shape, options);
  return opt.run();
}

}  // namespace clumpkit
