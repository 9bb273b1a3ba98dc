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
constexpr double kPi = std::numbers::pi;

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
    threads_ = o.threads > 0 ? o.threads : omp_get_max_threads();
    step_ = 0.01 * ctx_.size;
  }

  FillResult run() {
    const auto t0 = std::chrono::steady_clock::now();
    Spheres s;
    FillResult res;
    res.tolerance = ctx_.tolerance;
    if (o_.spheres > 0 && o_.max_error <= 0) {
      budget_mode(s);
    } else {
      target_mode(s, o_.spheres > 0 ? o_.spheres : o_.max_spheres);
    }
    ctx_.enforce_containment(s);
    const auto err = ctx_.errors(s);
    res.spheres = s;
    res.error = err.metric;
    res.target_reached = o_.max_error <= 0 || err.metric <= o_.max_error;
    res.report = {
        {"algorithm",
         "lazy-greedy coverage seeding, joint centre/radius descent on the "
         "ray-sampled symmetric difference, swap moves, pruning"},
        {"grid_cell", ctx_.grid.h},
        {"candidates", cand_.size()},
        {"objective_evaluations", evaluations_},
        {"descent_iterations", iterations_},
        {"symmetric_difference", err.symmetric_difference},
        {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()},
        {"history", history_}};
    return res;
  }

 private:
  double objective(const Spheres& s) {
    ++evaluations_;
    return ctx_.objective(s);
  }

  // ---- seeding -------------------------------------------------------------------------------
  void mark(std::vector<std::uint8_t>& covered, const Sphere& s) const {
    const auto& g = ctx_.grid;
    const Eigen::Vector3d q = (s.center - g.origin) / g.h;
    const int reach = static_cast<int>(std::ceil(s.radius / g.h)) + 1;
    const int ci = static_cast<int>(std::lround(q.x())), cj = static_cast<int>(std::lround(q.y())),
              ck = static_cast<int>(std::lround(q.z()));
    for (int k = std::max(0, ck - reach); k <= std::min(g.n.z() - 1, ck + reach); ++k)
      for (int j = std::max(0, cj - reach); j <= std::min(g.n.y() - 1, cj + reach); ++j)
        for (int i = std::max(0, ci - reach); i <= std::min(g.n.x() - 1, ci + reach); ++i)
          if ((g.center(i, j, k) - s.center).squaredNorm() <= s.radius * s.radius)
            covered[g.index(i, j, k)] = 1;
  }

  // Uncovered inside volume (in voxels) within the ball; sub-sampled for large balls.
  double gain(const std::vector<std::uint8_t>& covered, std::int64_t v, double r) const {
    const auto& g = ctx_.grid;
    const int ci = static_cast<int>(v % g.n.x()), cj = static_cast<int>((v / g.n.x()) % g.n.y()),
              ck = static_cast<int>(v / (static_cast<std::int64_t>(g.n.x()) * g.n.y()));
    const int s = std::max(1, static_cast<int>(r / (5.0 * g.h)));
    const int reach = static_cast<int>(r / g.h) / s * s;
    const double r2 = (r / g.h) * (r / g.h);
    double count = 0.0;
    for (int dk = -reach; dk <= reach; dk += s) {
      const int k = ck + dk;
      if (k < 0 || k >= g.n.z()) continue;
      for (int dj = -reach; dj <= reach; dj += s) {
        const int j = cj + dj;
        if (j < 0 || j >= g.n.y()) continue;
        for (int di = -reach; di <= reach; di += s) {
          const int i = ci + di;
          if (i < 0 || i >= g.n.x()) continue;
          if (di * di + dj * dj + dk * dk > r2) continue;
          const std::int64_t idx = g.index(i, j, k);
          if (g.inside[idx] && !covered[idx]) count += 1.0;
        }
      }
    }
    return count * s * s * s;
  }

  // Adds up to `count` spheres by lazy-greedy maximum coverage. Returns how many were added.
  int seed(Spheres& spheres, int count) const {
    const auto& g = ctx_.grid;
    std::vector<std::uint8_t> covered(g.size(), 0);
    for (const Sphere& s : spheres) mark(covered, s);
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
      const double rho = std::min(ctx_.tolerance - g.sdf[cand_[c]], cap_) / g.h;
      pq.push({4.0 / 3.0 * kPi * rho * rho * rho + 8.0, -1, c});
    }
    int added = 0;
    for (int round = 0; round < count && !pq.empty(); ++round) {
      while (!pq.empty()) {
        Item top = pq.top();
        pq.pop();
        if (top.round == round) {
          if (top.bound < 0.5) return added;  // nothing left to cover
          Sphere s;
          s.center = g.center(0, 0, 0);
          const std::int64_t v = cand_[top.cand];
          s.center +=
              g.h * Eigen::Vector3d(
                        static_cast<double>(v % g.n.x()),
                        static_cast<double>((v / g.n.x()) % g.n.y()),
                        static_cast<double>(v / (static_cast<std::int64_t>(g.n.x()) * g.n.y())));
          s.radius = std::min(ctx_.max_radius(s.center), cap_);
          if (s.radius < std::max(o_.min_radius, 1e-6 * ctx_.size)) continue;  // drop candidate
          spheres.push_back(s);
          mark(covered, s);
          ++added;
          break;
        }
        const double rho = std::min(ctx_.tolerance - g.sdf[cand_[top.cand]], cap_);
        pq.push({gain(covered, cand_[top.cand], rho), round, top.cand});
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
      const double da = 4.0 * kPi * s[i].radius * s[i].radius / static_cast<double>(dirs_.size());
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
      const double r = s[i].radius, norm = kPi * r * r;
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

  // ---- swaps and pruning ---------------------------------------------------------------------
  // Objective increase when each sphere is removed.
  std::vector<double> contributions(const Spheres& s) {
    std::vector<double> d;
    ++evaluations_;
    ctx_.objective(s, &d);
    return d;
  }

  void budget_mode(Spheres& s) {
    const int n = o_.spheres;
    // Multi-start: the plain coverage greedy opens with the largest sphere, which can trap the
    // descent (a flat pill); starts whose radii are capped near the equal-volume radius of n
    // spheres spread the spheres out. The best start after a short descent goes on.
    const double r_eq = std::cbrt(3.0 * ctx_.cache->shape_volume() / (4.0 * kPi * n));
    double best_f = std::numeric_limits<double>::infinity();
    Spheres best;
    for (const double cap : {std::numeric_limits<double>::infinity(), 1.25 * r_eq, r_eq}) {
      cap_ = cap;
      step_ = 0.01 * ctx_.size;
      Spheres t;
      seed(t, n);
      const double ft = refine(t, 15);
      history_.push_back({{"stage", "start"},
                          {"radius_cap", std::isinf(cap) ? -1.0 : cap},
                          {"spheres", t.size()},
                          {"objective", ft}});
      if (ft < best_f) {
        best_f = ft;
        best = std::move(t);
      }
    }
    cap_ = std::numeric_limits<double>::infinity();
    s = std::move(best);
    double f = refine(s, 40);
    history_.push_back({{"stage", "seed+refine"}, {"spheres", s.size()}, {"objective", f}});
    const int rounds = std::clamp(120 / std::max(1, n), 2, 8);
    for (int round = 0; round < rounds && !s.empty(); ++round) {
      const auto d = contributions(s);
      const size_t worst = static_cast<size_t>(std::min_element(d.begin(), d.end()) - d.begin());
      Spheres t = s;
      t.erase(t.begin() + static_cast<std::ptrdiff_t>(worst));
      if (seed(t, 1) == 0) break;
      const double saved_step = step_;
      const double ft = refine(t, 12);
      if (ft < f - 1e-6 * f) {
        s = std::move(t);
        f = ft;
        history_.push_back({{"stage", "swap"}, {"spheres", s.size()}, {"objective", f}});
      } else {
        step_ = saved_step;
        break;
      }
    }
    // A sphere count below the budget is allowed only if the shape is fully covered already.
    if (static_cast<int>(s.size()) < n) {
      seed(s, n - static_cast<int>(s.size()));
      f = refine(s, 20);
    }
  }

  void target_mode(Spheres& s, int cap) {
    int add = 1;
    double err = 1.0;
    while (static_cast<int>(s.size()) < cap) {
      const int got = seed(s, std::min(add, cap - static_cast<int>(s.size())));
      refine(s, 12);
      err = ctx_.errors(s).metric;
      history_.push_back({{"stage", "grow"}, {"spheres", s.size()}, {"error", err}});
      if (err <= o_.max_error || got == 0) break;
      add = std::max(1, static_cast<int>(s.size()) / 12);
    }
    if (err > o_.max_error) {
      refine(s, 40);
      return;
    }
    // Drop the least useful spheres while the target still holds.
    for (int guard = 0; guard < 1000 && s.size() > 1; ++guard) {
      const auto d = contributions(s);
      const size_t worst = static_cast<size_t>(std::min_element(d.begin(), d.end()) - d.begin());
      Spheres t = s;
      t.erase(t.begin() + static_cast<std::ptrdiff_t>(worst));
      refine(t, 8);
      const double e = ctx_.errors(t).metric;
      if (e > o_.max_error) break;
      s = std::move(t);
      history_.push_back({{"stage", "prune"}, {"spheres", s.size()}, {"error", e}});
    }
  }

  FillContext ctx_;
  FillOptions o_;
  std::vector<Eigen::Vector3d> dirs_;
  std::vector<std::int64_t> cand_;
  int threads_ = 1;
  double step_ = 0.0;
  double cap_ = std::numeric_limits<double>::infinity();  // radius cap of seeded spheres, m
  std::int64_t evaluations_ = 0, iterations_ = 0;
  nlohmann::json history_ = nlohmann::json::array();
};

}  // namespace

FillResult optimal_fill(const FillShape& shape, const FillOptions& options) {
  Optimiser opt(shape, options);
  return opt.run();
}

}  // namespace clumpkit
