#include "clumpkit/calibrate/diagnosis.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <tuple>

#include "clumpkit/core/error.hpp"
#include "clumpkit/rigs/catalogue.hpp"

namespace clumpkit::calibrate {

namespace {

// Regularised upper incomplete gamma Q(a, x) (series for x < a + 1, continued fraction beyond).
double gamma_q(double a, double x) {
  if (x <= 0) return 1.0;
  const double gln = std::lgamma(a);
  if (x < a + 1.0) {
    double sum = 1.0 / a, del = sum, ap = a;
    for (int n = 0; n < 1000; ++n) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-15) break;
    }
    return 1.0 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

using Values = std::map<std::string, SimulatedValue>;

// Response surrogate of one candidate through its simulated points (theta, values): a line
// through two points, a least-squares parabola through three or more, continued as a straight
// line (its tangent) beyond the points. Each point is a mean of a few noisy repeats, so the
// surrogate smooths rather than interpolates: a piecewise-linear interpolant takes its slope
// from the two nearest points, and two nearby refinement points give a slope that is mostly
// seed noise (and with it a fitted uncertainty several times too small).
// A rig's response over a candidate's whole range is often no parabola (the packing falls
// fast with the first bit of cohesion, then levels off; a heap's angle rises slowly, then
// steeply): where the parabola misses its points by more than their seed noise (a lack-of-fit
// chi2 test at 1 %), the points farthest from the `focus` (where the fit is being made) are
// dropped, down to three, so the surrogate is local where it must be and smooth where it can be.
struct Surrogate {
  /// A fit misses its points by more than their seed noise when a miss this large has a
  /// probability below this (chi2 test).
  static constexpr double kLackOfFit = 0.01;
  std::vector<std::pair<double, Values>> points;  // sorted by theta

  void add(double theta, Values v) {
    for (auto& p : points)
      if (p.first == theta) {
        p.second = std::move(v);
        coef.clear();
        return;
      }
    points.emplace_back(theta, std::move(v));
    std::sort(points.begin(), points.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    coef.clear();
  }
  // Where the next fit is made, and the pooled seed-to-seed spread of one run per observable
  // (the noise the lack-of-fit test weighs the points' misses by).
  void aim(double theta, const Values& pooled) {
    focus = theta;
    run_var.clear();
    for (const auto& [k, v] : pooled)
      if (v.n >= 2 && std::isfinite(v.std) && v.std > 0) run_var[k] = v.std * v.std;
    coef.clear();
  }
  double value(const std::string& key, double theta) const {
    const Poly& c = poly(key);
    auto at = [&](double t) {
      const double x = (t - c.mid) / c.half;
      return c.a + x * (c.b + x * c.c);
    };
    auto slope = [&](double t) {
      const double x = (t - c.mid) / c.half;
      return (c.b + 2.0 * c.c * x) / c.half;
    };
    if (theta < c.lo) return at(c.lo) + slope(c.lo) * (theta - c.lo);
    if (theta > c.hi) return at(c.hi) + slope(c.hi) * (theta - c.hi);
    return at(theta);
  }
  // Variance of a simulated mean through the surrogate, averaged over its points: each point's
  // own seed scatter (std^2/n) where it has repeats, the pooled per-run variance `run_var` for
  // a single-run (screening) point; never below the baseline's `run_var / base_n`. Heaps with
  // more rolling friction scatter more than the baseline's (tiny scale: 2-4 deg against 1.6),
  // so the baseline's scatter alone understated the fitted uncertainty.
  double noise_var(const std::string& key, double run_var, int base_n) const {
    const double floor = base_n > 0 ? run_var / base_n : run_var;
    double sum = 0.0;
    int k = 0;
    for (const auto& [t, v] : points) {
      const auto it = v.find(key);
      if (it == v.end()) continue;
      sum += it->second.n >= 2 ? it->second.std * it->second.std / it->second.n : run_var;
      ++k;
    }
    return k > 0 ? std::max(floor, sum / k) : floor;
  }

 private:
  struct Poly {
    double mid = 0, half = 1, a = 0, b = 0, c = 0;  ///< a + b x + c x^2, x = (t - mid) / half
    double lo = 0, hi = 0;                          ///< span of the points it follows
  };
  mutable std::map<std::string, Poly> coef;
  double focus = std::numeric_limits<double>::quiet_NaN();
  std::map<std::string, double> run_var;

  // (theta, mean, repeats) of the points, for one observable.
  struct Pt {
    double t, y;
    int n;
  };
  // Lack of fit of `p` at the points, in units of their seed noise (`var`: one run's variance),
  // as the probability of a miss this large from noise alone.
  static double fits_within_noise(const Poly& p, const std::vector<Pt>& pts, double var) {
    double miss = 0.0;
    for (const Pt& q : pts) {
      const double x = (q.t - p.mid) / p.half, r = p.a + x * (p.b + x * p.c) - q.y;
      miss += r * r * std::max(1, q.n) / var;
    }
    const int dof = static_cast<int>(pts.size()) - (p.c != 0.0 ? 3 : 2);
    return dof > 0 ? chi2_survival(miss, dof) : 1.0;
  }
  // `var`: one run's seed variance (0: unknown).
  static Poly fit(const std::vector<Pt>& pts, double var) {
    Poly p;
    const size_t n = pts.size();
    p.lo = pts.front().t;
    p.hi = pts.front().t;
    for (const Pt& q : pts) {
      p.lo = std::min(p.lo, q.t);
      p.hi = std::max(p.hi, q.t);
    }
    p.mid = 0.5 * (p.lo + p.hi);
    p.half = std::max(0.5 * (p.hi - p.lo), 1e-300);
    if (n == 1) {
      p.a = pts[0].y;
    } else if (n == 2) {
      const bool up = pts[0].t < pts[1].t;
      const double y0 = up ? pts[0].y : pts[1].y, y1 = up ? pts[1].y : pts[0].y;
      p.a = 0.5 * (y0 + y1);
      p.b = 0.5 * (y1 - y0);  // x runs from -1 to 1 between the two points
    } else {
      // Normal equations of the least-squares parabola in x (well conditioned: |x| <= 1).
      double S[5] = {0, 0, 0, 0, 0}, T[3] = {0, 0, 0};
      for (const Pt& q : pts) {
        const double x = (q.t - p.mid) / p.half;
        double xk = 1.0;
        for (int k = 0; k < 5; ++k) {
          if (k < 3) T[k] += xk * q.y;
          S[k] += xk;
          xk *= x;
        }
      }
      Eigen::Matrix3d M;
      M << S[0], S[1], S[2], S[1], S[2], S[3], S[2], S[3], S[4];
      const Eigen::Vector3d q = M.ldlt().solve(Eigen::Vector3d(T[0], T[1], T[2]));
      p.a = q[0];
      p.b = q[1];
      p.c = q[2];
      // A parabola that turns over between the points is seed noise, not physics (the rigs'
      // responses to one effect's strength are monotone over such a span), and its extremum
      // would trap the fit: the least-squares line instead. Where the line misses the points
      // by more than their seed noise (`var`, one run's variance), the least-squares parabola
      // that is monotone over the span: its vertex at one end of it (a response that barely
      // moves at first and then fast, or one that levels off), whichever misses them least.
      if ((p.b - 2.0 * p.c) * (p.b + 2.0 * p.c) < 0.0) {
        double best = std::numeric_limits<double>::infinity();
        Poly mono = p, line = p;
        // y = a + c u with u = (x - e)^2 (e = -1, +1), or u = x (the line).
        for (int form = 0; form < 3; ++form) {
          const double e = form == 0 ? -1.0 : 1.0;
          auto u_of = [&](double x) { return form == 2 ? x : (x - e) * (x - e); };
          double su = 0, sy = 0, suu = 0, suy = 0;
          for (const Pt& pt : pts) {
            const double u = u_of((pt.t - p.mid) / p.half);
            su += u;
            sy += pt.y;
            suu += u * u;
            suy += u * pt.y;
          }
          const double m = static_cast<double>(pts.size()), det = m * suu - su * su;
          if (det <= 0.0) continue;
          const double k = (m * suy - su * sy) / det, a0 = (sy - k * su) / m;
          double sse = 0;
          for (const Pt& pt : pts) {
            const double r = a0 + k * u_of((pt.t - p.mid) / p.half) - pt.y;
            sse += r * r;
          }
          if (form == 2) line.a = a0, line.b = k, line.c = 0.0;
          if (sse >= best) continue;
          best = sse;
          if (form == 2) {
            mono = line;
          } else {
            mono.a = a0 + k * e * e, mono.b = -2.0 * k * e, mono.c = k;
          }
        }
        p = var > 0.0 && fits_within_noise(line, pts, var) < kLackOfFit ? mono : line;
      }
    }
    return p;
  }

  const Poly& poly(const std::string& key) const {
    auto it = coef.find(key);
    if (it != coef.end()) return it->second;
    std::vector<Pt> pts;
    for (const auto& [t, v] : points) pts.push_back({t, v.at(key).mean, v.at(key).n});
    const auto rv = run_var.find(key);
    const double var = rv == run_var.end() ? 0.0 : rv->second;
    Poly p = fit(pts, var);
    if (std::isfinite(focus) && var > 0.0) {
      // Nearest the focus first; drop from the far end while the fit misses its points.
      std::stable_sort(pts.begin(), pts.end(), [&](const Pt& a, const Pt& b) {
        return std::abs(a.t - focus) < std::abs(b.t - focus);
      });
      // Never down to points so close that the response between them is mostly seed noise
      // (their slope, and with it the fitted uncertainty, would be noise): the points kept
      // must span a change of at least four standard errors of a two-repeat mean.
      auto spans_signal = [&](size_t n) {
        double lo = pts[0].y, hi = pts[0].y;
        for (size_t i = 1; i < n; ++i) lo = std::min(lo, pts[i].y), hi = std::max(hi, pts[i].y);
        return hi - lo >= 4.0 * std::sqrt(var / 2.0);
      };
      while (pts.size() > 3 && fits_within_noise(p, pts, var) < kLackOfFit &&
             spans_signal(pts.size() - 1)) {
        pts.pop_back();
        p = fit(pts, var);
      }
    }
    return coef.emplace(key, p).first->second;
  }
};

// Variance of each measurement's difference from the surrogate: the lab's and the
// simulations' (the same for every theta of one fit).
std::vector<double> fit_variances(const std::vector<Measurement>& ms, const Values& base,
                                  const Surrogate& s) {
  std::vector<double> var;
  for (const auto& m : ms) {
    const SimulatedValue& b = base.at(m.key());
    var.push_back(m.std * m.std / m.n + s.noise_var(m.key(), b.std * b.std, b.n));
  }
  return var;
}

double chi2_of(const std::vector<Measurement>& ms, const std::vector<double>& var,
               const Surrogate& s, double theta) {
  double chi2 = 0;
  for (size_t i = 0; i < ms.size(); ++i) {
    const double d = s.value(ms[i].key(), theta) - ms[i].value;
    chi2 += d * d / var[i];
  }
  return chi2;
}

struct Fit {
  double theta = 0, chi2 = 0, sigma = 0;
  double lo95 = 0, hi95 = 0;  ///< Delta chi2 = 4 on the surrogate (asymmetric where it levels off)
};

Fit fit_surrogate(const std::vector<Measurement>& ms, const Values& base, const Surrogate& s,
                  double lo, double hi) {
  const int n = 2000;
  std::vector<double> th(n + 1), c(n + 1);
  Fit f;
  f.chi2 = std::numeric_limits<double>::infinity();
  int best = 0;
  const std::vector<double> var = fit_variances(ms, base, s);
  for (int i = 0; i <= n; ++i) {
    th[i] = lo + (hi - lo) * i / n;
    c[i] = chi2_of(ms, var, s, th[i]);
    if (c[i] < f.chi2) {
      f.chi2 = c[i];
      best = i;
    }
  }
  f.theta = th[best];
  // Delta chi2 = 1 interval on the surrogate; an open side extends to the range bound.
  int a = best, b = best;
  while (a > 0 && c[a] < f.chi2 + 1.0) --a;
  while (b < n && c[b] < f.chi2 + 1.0) ++b;
  f.sigma = 0.5 * (th[b] - th[a]);
  while (a > 0 && c[a] < f.chi2 + 4.0) --a;
  while (b < n && c[b] < f.chi2 + 4.0) ++b;
  f.lo95 = th[a];
  f.hi95 = th[b];
  return f;
}

// Two continuous candidates at once, on the sum of their one-effect surrogates: the responses
// to a and to b add (each surrogate's change from its own baseline), plus `offset`, what a run
// of the pair showed the sum to miss (the interaction). chi2 on a grid over both ranges; each
// parameter's uncertainty from its profile (the least chi2 over the other).
struct PairFitResult {
  double ta = 0, tb = 0, chi2 = std::numeric_limits<double>::infinity();
  double sa = 0, sb = 0, lo_a = 0, hi_a = 0, lo_b = 0, hi_b = 0;
};

PairFitResult fit_pair(const std::vector<Measurement>& ms, const Values& pooled, const Surrogate& a,
                       double base_a, std::pair<double, double> range_a, const Surrogate& b,
                       double base_b, std::pair<double, double> range_b,
                       const std::vector<double>& offset) {
  constexpr int kGrid = 160;
  const size_t n = ms.size();
  const std::vector<double> va = fit_variances(ms, pooled, a), vb = fit_variances(ms, pooled, b);
  std::vector<double> var(n);
  for (size_t k = 0; k < n; ++k) var[k] = va[k] + vb[k] - ms[k].std * ms[k].std / ms[k].n;
  auto axis = [](std::pair<double, double> r, int i) {
    return r.first + (r.second - r.first) * i / kGrid;
  };
  // Each surrogate's change from its baseline, on its grid.
  std::vector<double> da((kGrid + 1) * n), db((kGrid + 1) * n);
  for (size_t k = 0; k < n; ++k) {
    const std::string key = ms[k].key();
    const double a0 = a.value(key, base_a), b0 = b.value(key, base_b);
    for (int i = 0; i <= kGrid; ++i) {
      da[i * n + k] = a.value(key, axis(range_a, i)) - a0;
      db[i * n + k] = b.value(key, axis(range_b, i)) - b0;
    }
  }
  // The residual at the baselines: the baseline's mean (a's surrogate there) against the data.
  std::vector<double> r0(n);
  for (size_t k = 0; k < n; ++k) r0[k] = a.value(ms[k].key(), base_a) + offset[k] - ms[k].value;
  std::vector<double> chi2((kGrid + 1) * (kGrid + 1));
  PairFitResult f;
  int bi = 0, bj = 0;
  for (int i = 0; i <= kGrid; ++i)
    for (int j = 0; j <= kGrid; ++j) {
      double c = 0;
      for (size_t k = 0; k < n; ++k) {
        const double d = r0[k] + da[i * n + k] + db[j * n + k];
        c += d * d / var[k];
      }
      chi2[i * (kGrid + 1) + j] = c;
      if (c < f.chi2) f.chi2 = c, bi = i, bj = j;
    }
  f.ta = axis(range_a, bi);
  f.tb = axis(range_b, bj);
  std::vector<double> pa(kGrid + 1, std::numeric_limits<double>::infinity()), pb = pa;
  for (int i = 0; i <= kGrid; ++i)
    for (int j = 0; j <= kGrid; ++j) {
      pa[i] = std::min(pa[i], chi2[i * (kGrid + 1) + j]);
      pb[j] = std::min(pb[j], chi2[i * (kGrid + 1) + j]);
    }
  auto interval = [&](const std::vector<double>& prof, int best, std::pair<double, double> r,
                      double up) {
    int lo = best, hi = best;
    while (lo > 0 && prof[lo] < f.chi2 + up) --lo;
    while (hi < kGrid && prof[hi] < f.chi2 + up) ++hi;
    return std::pair<double, double>{axis(r, lo), axis(r, hi)};
  };
  const auto a1 = interval(pa, bi, range_a, 1.0), b1 = interval(pb, bj, range_b, 1.0);
  f.sa = 0.5 * (a1.second - a1.first);
  f.sb = 0.5 * (b1.second - b1.first);
  std::tie(f.lo_a, f.hi_a) = interval(pa, bi, range_a, 4.0);
  std::tie(f.lo_b, f.hi_b) = interval(pb, bj, range_b, 4.0);
  return f;
}

std::string observable_name(const Measurement& m) {
  const std::string s = m.setting_text();
  return fmt::format("{} {}{} {}", m.rig, m.sample, s.empty() ? "" : " [" + s + "]", m.quantity);
}

}  // namespace

std::string interval_text(const CandidateResult& r) {
  if (r.candidate.discrete) return "-";
  return fmt::format("{:.3g} to {:.3g}", r.fitted_lo, r.fitted_hi);
}

std::string parameter_text(const CandidateResult& r) {
  if (!r.with) return r.candidate.parameter;
  const EffectCandidate& w = r.with->candidate;
  return fmt::format("{} (with {}: {} = {})", r.candidate.parameter, w.effect, w.parameter,
                     w.format(r.with->fitted));
}

std::string chi2_source_text(const CandidateResult& r) {
  if (r.chi2_source == "nearest_run") return "run at " + r.candidate.format(r.chi2_at);
  return r.chi2_source;
}

double chi2_survival(double x, int dof) {
  return gamma_q(0.5 * dof, 0.5 * x);
}

Diagnosis diagnose(const ParticleModel& base, const std::vector<Measurement>& ms, Simulator& sim,
                   const DiagnoseOptions& o) {
  Diagnosis d;
  const long runs0 = sim.runs();
  auto say = [&](const std::string& s) {
    if (o.progress) o.progress(s);
  };
  // The seed-to-seed spread of every observable, pooled over all the variants simulated
  // (comparison.hpp): the spread of two repeats of one model is too uncertain to weigh by.
  SpreadPool pool(ms);
  std::set<std::string> pooled_models;
  auto simulate = [&](const ParticleModel& m, int repeats) {
    Values v = simulate_measurements(sim, m, ms, o.scale, repeats, o.seed);
    // Keyed by the repeats too: a screened level (one repeat, no spread) confirmed with every
    // repeat adds its spread then.
    if (pooled_models.insert(model_fingerprint(m) + "|" + std::to_string(repeats)).second)
      pool.add(v);
    return v;
  };
  // Runs that are known in advance are announced together, so a simulator can run them side
  // by side; the results (and so the diagnosis) do not depend on it.
  const std::vector<SimRequest> requests = requests_for(ms, o.scale);
  auto prefetch = [&](const std::vector<ParticleModel>& models, int repeats) {
    std::vector<SimJob> jobs;
    for (const auto& m : models)
      for (const auto& r : requests) jobs.push_back({m, r});
    try {
      sim.prefetch(jobs, repeats, o.seed);
    } catch (const NumericalError&) {
      // The failing run is made again where it is needed, and handled there.
    }
  };
  const int n = static_cast<int>(ms.size());
  const double ln_n = std::log(std::max(1, n));

  const std::vector<EffectCandidate> cands = effect_candidates(base, o.effects, &d.skipped);
  const int screen = std::max(1, std::min(o.screen_repeats, o.repeats));
  {
    std::vector<ParticleModel> first;
    for (const auto& c : cands) {
      if (c.discrete)
        for (double level : c.levels) first.push_back(c.apply(base, level));
      else
        first.push_back(c.apply(base, c.probe));
    }
    say(
        fmt::format("{} model variants to simulate first: the baseline ({} repeats), probes and "
                    "levels ({} repeat{} each)",
                    first.size() + 1, o.repeats, screen, screen == 1 ? "" : "s"));
    // The baseline's runs, then the screen's, each set side by side.
    if (screen == o.repeats) {
      first.insert(first.begin(), base);
      prefetch(first, o.repeats);
    } else {
      prefetch({base}, o.repeats);
      prefetch(first, screen);
    }
  }
  say("baseline model " + base.name);
  const Values s0 = simulate(base, o.repeats);

  struct Work {
    EffectCandidate c;
    Surrogate s;
    Fit fit;
    Values at_fit;
    bool have_at_fit = false;
    bool dropped = false;  ///< a run at its fitted value failed (reason in d.skipped)
    std::string source = "run";
    double at = 0.0;  ///< parameter value of at_fit
    /// The values the rigs could measure: [lo_ok, hi_ok] within the candidate's range, narrowed
    /// at a value where a run failed (`limit` says where and why); fits stay short of it
    /// (fit_range), by half the way from the nearest measured value.
    double lo_ok = 0.0, hi_ok = 0.0;
    std::string limit;
    int failures = 0;
    int steps_left = 0;  ///< refinement steps still allowed
    int extra_left = 0;  ///< further steps while it leads and has not converged
    /// Discrete: every level's runs (the screen's, replaced by a confirmation's).
    std::vector<std::pair<double, Values>> level_runs;
  };
  std::vector<Work> work;
  // A failed run at theta: the rigs cannot measure there (a heap that spreads flat, or that the
  // lifting tube carries off; a run that blows up). The candidate's range ends at theta, on the
  // side away from the nearest value that was measured.
  auto cannot_measure = [&](Work& w, double theta, const std::string& why) {
    double nearest = w.c.baseline;
    for (const auto& p : w.s.points)
      if (std::abs(p.first - theta) < std::abs(nearest - theta)) nearest = p.first;
    if (theta > nearest)
      w.hi_ok = std::min(w.hi_ok, theta);
    else
      w.lo_ok = std::max(w.lo_ok, theta);
    ++w.failures;
    w.limit = "the rigs could not measure at " + w.c.format(theta) + ": " + why;
    say(fmt::format("{}: {}; fitting short of it", w.c.effect, w.limit));
  };
  // The range a fit may use: the measurable one, kept half the way short of a failed value
  // from the nearest measured value (so refinements bisect toward a failure).
  auto fit_range = [&](const Work& w) {
    double lo = w.lo_ok, hi = w.hi_ok;
    if (w.hi_ok < w.c.hi) {
      double g = lo;
      for (const auto& p : w.s.points)
        if (p.first < w.hi_ok) g = std::max(g, p.first);
      hi = 0.5 * (g + w.hi_ok);
    }
    if (w.lo_ok > w.c.lo) {
      double g = hi;
      for (const auto& p : w.s.points)
        if (p.first > w.lo_ok) g = std::min(g, p.first);
      lo = 0.5 * (g + w.lo_ok);
    }
    return std::pair<double, double>{lo, hi};
  };
  // The surrogate is aimed at the last fit (where the new run was made) before it is fitted
  // again.
  auto refit = [&](Work& w) {
    const auto [lo, hi] = fit_range(w);
    const Values pooled = pool.pooled(s0);
    w.s.aim(w.fit.theta, pooled);
    return fit_surrogate(ms, pooled, w.s, lo, hi);
  };
  for (const auto& c : cands) {
    Work w;
    w.c = c;
    w.lo_ok = c.lo;
    w.hi_ok = c.hi;
    w.steps_left = o.refinements;
    w.extra_left = o.extra_refinements;
    // A variant the rigs cannot measure (a heap that spreads flat, a run that blows up) rules
    // the candidate out with the reason; it does not end the diagnosis.
    try {
      if (c.discrete) {
        double best = std::numeric_limits<double>::infinity();
        for (size_t i = 0; i < c.levels.size(); ++i) {
          say(fmt::format("{}: {}", c.effect, c.level_names[i]));
          Values v = simulate(c.apply(base, c.levels[i]), screen);
          const double chi2 = compare(ms, pool.pooled(v), 1).chi2;
          if (chi2 < best) {
            best = chi2;
            w.fit = {c.levels[i], chi2, 0.0};
            w.at_fit = v;
            w.at = c.levels[i];
            w.have_at_fit = true;
          }
          w.level_runs.emplace_back(c.levels[i], std::move(v));
        }
      } else {
        say(fmt::format("{}: sensitivity at {} = {}", c.effect, c.parameter, c.format(c.probe)));
        w.s.add(c.baseline, s0);
        double probe = c.probe;
        Values v;
        try {
          v = simulate(c.apply(base, probe), screen);
        } catch (const NumericalError& e) {
          // Once more, half the way back to the baseline.
          cannot_measure(w, probe, e.what());
          probe = 0.5 * (c.baseline + probe);
          say(fmt::format("{}: sensitivity at {} = {}", c.effect, c.parameter, c.format(probe)));
          v = simulate(c.apply(base, probe), screen);
        }
        w.s.add(probe, std::move(v));
        w.fit = refit(w);
      }
    } catch (const NumericalError& e) {
      say(fmt::format("{}: not tried: {}", c.effect, e.what()));
      d.skipped.push_back(c.effect + ": its variant could not be simulated: " + e.what());
      continue;
    }
    work.push_back(std::move(w));
  }
  // The other side of the baseline. A probe on one side says little about the other (a heap
  // barely feels pill-pill friction above Table 1's 0.47 and a lot below it), so where the data
  // are inconsistent with the baseline, a candidate's surrogate on its unprobed side is a guess:
  // one screening run at the mirrored probe gives it a point there before the candidates are
  // ranked. It is made where the candidate's fit lies on that side, and where its line cannot
  // explain the data without pointing past the probe (below): the slope of a one-repeat probe
  // is seed noise where the response on the probed side is flat, and with Table 1's pills a
  // lower pill-pill friction went unseen because a noisy probe pulled its fit up.
  const double p_screened = chi2_survival(compare(ms, pool.pooled(s0), 0).chi2, n);
  const bool inconsistent = p_screened < o.p_inconsistent;
  // A baseline the screen leaves consistent with the data (p >= p_screen_only) gets no verdict
  // whatever the refinements find (a verdict needs p < p_inconsistent): the candidates keep
  // their screened fits (chi2 from the surrogate; discrete levels from their screening runs),
  // and no refinement or confirmation run is made (with nothing hidden, half of a diagnosis).
  const bool screen_only = p_screened >= o.p_screen_only;
  if (screen_only) {
    d.screen_only = true;
    say(
        fmt::format("the baseline is consistent with the data after the screen (p = {:.3g}): "
                    "no refinement or confirmation runs",
                    p_screened));
  }
  // One more screening run for each (candidate, value), side by side, and a refit.
  auto screen_more = [&](const std::vector<std::pair<Work*, double>>& runs, const char* where) {
    std::vector<ParticleModel> models;
    for (const auto& [w, v] : runs) models.push_back(w->c.apply(base, v));
    prefetch(models, screen);
    for (const auto& [w, v] : runs) {
      say(fmt::format("{}: sensitivity {}, at {} = {}", w->c.effect, where, w->c.parameter,
                      w->c.format(v)));
      try {
        w->s.add(v, simulate(w->c.apply(base, v), screen));
      } catch (const NumericalError& e) {
        cannot_measure(*w, v, e.what());
      }
      w->fit = refit(*w);
    }
  };
  // The probe of a continuous candidate that has only its screen (baseline and probe), or NaN.
  auto probe_of = [](const Work& w) {
    if (w.c.discrete || w.s.points.size() != 2) return std::numeric_limits<double>::quiet_NaN();
    return w.s.points[0].first == w.c.baseline ? w.s.points[1].first : w.s.points[0].first;
  };
  // Beyond the probe. A response can stay flat up to the probe and set in past it (the heap
  // barely feels restitution from Table 1's 0.2 to 0.5 and a lot at 0.7): a candidate whose
  // line through the baseline and the probe points past the probe, removes part of the misfit
  // (chi2 down by 4 or more) but still cannot explain the data gets one screening run at twice
  // the probe's step, before the candidates are ranked; otherwise a competitor that explains
  // the data at once (a lower rolling friction) would take the verdict unchallenged. Returns that
  // value, or NaN where no such run is due.
  const auto further_on = [&](const Work& w) {
    constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
    const double probe = probe_of(w);
    const double step = probe - w.c.baseline;
    if (std::isnan(probe) || (w.fit.theta - probe) * step <= 0.0) return kNone;  // not past it
    const std::vector<double> var = fit_variances(ms, pool.pooled(s0), w.s);
    if (chi2_of(ms, var, w.s, w.c.baseline) - w.fit.chi2 < 4.0) return kNone;
    if (chi2_survival(w.fit.chi2, n) >= o.p_inconsistent) return kNone;  // explains the data
    const double f = std::clamp(w.c.baseline + 2.0 * step, w.lo_ok, w.hi_ok);
    return f != probe ? f : kNone;
  };
  if (inconsistent) {
    std::vector<std::pair<Work*, double>> mirrors;
    for (Work& w : work) {
      const double probe = probe_of(w);
      if (std::isnan(probe)) continue;
      const bool other_side = (probe - w.c.baseline) * (w.fit.theta - w.c.baseline) < 0.0;
      const bool unexplained =
          chi2_survival(w.fit.chi2, n) < o.p_inconsistent && std::isnan(further_on(w));
      if (!other_side && !unexplained) continue;
      const double m = std::clamp(2.0 * w.c.baseline - probe, w.lo_ok, w.hi_ok);
      if (m != w.c.baseline) mirrors.emplace_back(&w, m);
    }
    screen_more(mirrors, "on the other side");
    std::vector<std::pair<Work*, double>> further;
    for (Work& w : work) {
      const double f = further_on(w);
      if (!std::isnan(f)) further.emplace_back(&w, f);
    }
    screen_more(further, "further on");
  }
  // Refine the leading continuous candidates with real runs at their fitted values.
  std::vector<size_t> order(work.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return work[a].fit.chi2 < work[b].fit.chi2; });
  // Step by step over the leading candidates (each candidate's sequence is its own, so the
  // order does not change any result), so that one step's runs can go side by side.
  // A failed run narrows the candidate's range and costs it no step: up to two failures each
  // are followed by one more refinement (short of the failure) than `refinements`.
  std::vector<Work*> refining;
  for (size_t r = 0; r < order.size() && static_cast<int>(r) < o.refine_top; ++r)
    if (!work[order[r]].c.discrete && o.refinements > 0 && !screen_only)
      refining.push_back(&work[order[r]]);
  while (!refining.empty()) {
    std::vector<ParticleModel> models;
    for (Work* w : refining) models.push_back(w->c.apply(base, w->fit.theta));
    prefetch(models, o.repeats);
    std::vector<Work*> still;
    for (Work* w : refining) {
      say(fmt::format("{}: refining at {}", w->c.effect, w->c.format(w->fit.theta)));
      int& left = w->steps_left;
      --left;
      Values v;
      try {
        v = simulate(w->c.apply(base, w->fit.theta), o.repeats);
      } catch (const NumericalError& e) {
        cannot_measure(*w, w->fit.theta, e.what());
        w->fit = refit(*w);
        if (w->failures <= 2) ++left;
        if (left > 0) still.push_back(w);
        continue;
      }
      w->s.add(w->fit.theta, v);
      const Fit next = refit(*w);
      const bool converged =
          std::abs(next.theta - w->fit.theta) <= 0.25 * std::max(next.sigma, 1e-12);
      w->fit = next;
      if (!converged && left == 0 && w->extra_left > 0 && inconsistent) {
        // The leader (by the surrogates' chi2) gets a few more steps to converge, where there is
        // a misfit to converge on (with data the baseline already explains, its fit wanders
        // with the runs' noise: 4 steps of pill-wall friction in the mini case with nothing
        // hidden, 0.61, 0.56, 0.60, 0.56).
        bool leads = true;
        for (const Work& other : work)
          if (&other != w && !other.dropped && other.fit.chi2 < w->fit.chi2) leads = false;
        if (leads) {
          --w->extra_left;
          ++left;
        }
      }
      if (!converged && left > 0) still.push_back(w);
    }
    refining = still;
  }
  // How each continuous candidate's chi2 at its fitted value is known. A simulated point within
  // a quarter of the fitted uncertainty serves (the refinement's own convergence test); a
  // candidate the surrogate puts far behind the best real run is not simulated again (at
  // mini scale each confirmation is 4-8 rig runs, and such candidates are usually pinned at a
  // bound of their range); every other candidate gets a confirmation run at its fitted value.
  const Values pooled0 = pool.pooled(s0);  // the pool is final for this decision
  double best_real = compare(ms, pooled0, 0).chi2;
  for (const Work& w : work) {
    if (w.dropped) continue;
    if (w.have_at_fit) best_real = std::min(best_real, compare(ms, pool.pooled(w.at_fit), 1).chi2);
    for (const auto& [t, v] : w.s.points)
      best_real = std::min(best_real, compare(ms, pool.pooled(v), 1).chi2);
  }
  auto full = [&](const Values& v) { return !v.empty() && v.begin()->second.n >= o.repeats; };
  std::vector<std::pair<Work*, double>> confirm;  // a candidate and the value to run it at
  for (Work& w : work) {
    if (w.dropped) continue;
    if (w.c.discrete) {
      // Every screened level that could lead is simulated again with every repeat: one
      // repeat's noise must not choose between levels (the CDT and EPSD rolling models both
      // lower a heap; the better-screened one is not always the better one).
      for (const auto& [level, v] : w.level_runs)
        if (!screen_only && !full(v) &&
            compare(ms, pool.pooled(v), 1).chi2 < best_real + o.confirm_margin)
          confirm.emplace_back(&w, level);
      continue;
    }
    if (w.have_at_fit) continue;
    // A point of the screen (one repeat) does not stand for a fit: only full-repeat runs do.
    const std::pair<double, Values>* nearest = nullptr;
    for (const auto& p : w.s.points)
      if (full(p.second) && std::abs(p.first - w.fit.theta) <= 0.25 * w.fit.sigma &&
          (!nearest || std::abs(p.first - w.fit.theta) < std::abs(nearest->first - w.fit.theta)))
        nearest = &p;
    if (nearest) {
      w.at_fit = nearest->second;
      w.at = nearest->first;
      w.source = nearest->first == w.fit.theta ? "run" : "nearest_run";
      w.have_at_fit = true;
    } else if (screen_only || w.fit.chi2 >= best_real + o.confirm_margin) {
      // The surrogate's prediction, each value with the variance the fit gave it.
      for (const auto& m : ms) {
        const SimulatedValue& b = pooled0.at(m.key());
        SimulatedValue v;
        v.n = b.n;
        v.mean = w.s.value(m.key(), w.fit.theta);
        v.std = b.n > 0 ? std::sqrt(w.s.noise_var(m.key(), b.std * b.std, b.n) * b.n) : b.std;
        w.at_fit[m.key()] = v;
      }
      w.at = w.fit.theta;
      w.source = "surrogate";
      w.have_at_fit = true;
      if (!screen_only)
        say(fmt::format(
            "{}: not confirmed: its surrogate chi2 at {} is {:.1f}, {:.1f} above the best run",
            w.c.effect, w.c.format(w.fit.theta), w.fit.chi2, w.fit.chi2 - best_real));
    } else {
      confirm.emplace_back(&w, w.fit.theta);
    }
  }
  {  // the confirmation runs, side by side
    std::vector<ParticleModel> models;
    for (const auto& [w, value] : confirm) models.push_back(w->c.apply(base, value));
    prefetch(models, o.repeats);
  }
  std::map<const Work*, std::string> level_failed;  // discrete: why a confirmed level failed
  for (const auto& [w, value] : confirm) {
    say(fmt::format("{}: confirming at {}", w->c.effect, w->c.format(value)));
    if (w->c.discrete) {
      for (auto& [level, v] : w->level_runs) {
        if (level != value) continue;
        try {
          v = simulate(w->c.apply(base, level), o.repeats);
        } catch (const NumericalError& e) {
          level_failed[w] = "the run at " + w->c.format(level) + " failed: " + e.what();
          v.clear();  // a level the rigs cannot measure is not chosen
        }
      }
      continue;
    }
    try {
      w->at_fit = simulate(w->c.apply(base, w->fit.theta), o.repeats);
    } catch (const NumericalError& e) {
      // A continuous candidate is confirmed once more, short of the failure.
      std::string why = e.what();
      bool confirmed = false;
      if (!w->c.discrete) {
        cannot_measure(*w, w->fit.theta, why);
        w->fit = refit(*w);
        say(fmt::format("{}: confirming at {}", w->c.effect, w->c.format(w->fit.theta)));
        try {
          w->at_fit = simulate(w->c.apply(base, w->fit.theta), o.repeats);
          confirmed = true;
        } catch (const NumericalError& e2) {
          why = e2.what();  // the reason at the value named below
        }
      }
      if (!confirmed) {
        d.skipped.push_back(w->c.effect + ": the run at its fitted value " +
                            w->c.format(w->fit.theta) + " failed: " + why);
        w->dropped = true;
        continue;
      }
    }
    w->s.add(w->fit.theta, w->at_fit);
    w->at = w->fit.theta;
    w->have_at_fit = true;
  }
  // A discrete candidate's level: the least chi2 among the levels run with every repeat (among
  // the screened ones where none was confirmed); dropped where every confirmed level failed.
  for (Work& w : work) {
    if (w.dropped || !w.c.discrete) continue;
    bool any_full = false;
    for (const auto& p : w.level_runs) any_full = any_full || full(p.second);
    if (!any_full && level_failed.count(&w)) {
      d.skipped.push_back(w.c.effect + ": " + level_failed[&w]);
      w.dropped = true;
      continue;
    }
    double best = std::numeric_limits<double>::infinity();
    for (const auto& [level, v] : w.level_runs) {
      if (v.empty() || (any_full && !full(v))) continue;
      const double chi2 = compare(ms, pool.pooled(v), 1).chi2;
      if (chi2 < best) {
        best = chi2;
        w.fit = {level, chi2, 0.0};
        w.at_fit = v;
        w.at = level;
        w.have_at_fit = true;
        w.source = full(v) ? "run" : "screen";
      }
    }
  }
  // Two effects at once. Where even the best single effect leaves the data unexplained (its
  // run's chi2 has p < p_inconsistent), two effects may be missing: one alone is fitted too
  // far (a hidden rolling friction and cohesion both raise the heap; cohesion alone, fitted to
  // the heaps, then lowers the cup too much), and the next diagnosis cannot add the other,
  // since the heaps already match. Every pair of continuous candidates is fitted on the sum of
  // their surrogates (no runs); the best `pair_top` that would beat the best single effect by
  // min_delta_bic with their second parameter paid for are run at their fit (every repeat),
  // and once more where that run moves the fit (the sum's miss at the run added as an offset).
  struct PairWork {
    Work* a = nullptr;
    Work* b = nullptr;
    PairFitResult fit;
    Values at_fit;
  };
  std::vector<PairWork> pairs;
  if (inconsistent && o.pairs && o.pair_top > 0 && n >= o.pair_min_observables) {
    const Values pooled = pool.pooled(s0);
    double best_single = std::numeric_limits<double>::infinity();
    for (const Work& w : work)
      if (!w.dropped && w.have_at_fit && w.source != "surrogate")
        best_single = std::min(best_single, compare(ms, pool.pooled(w.at_fit), 1).chi2);
    if (std::isfinite(best_single) && chi2_survival(best_single, n) < o.p_inconsistent) {
      const std::vector<double> no_offset(ms.size(), 0.0);
      auto fit_of = [&](PairWork& p, const std::vector<double>& offset) {
        p.fit = fit_pair(ms, pool.pooled(s0), p.a->s, p.a->c.baseline, fit_range(*p.a), p.b->s,
                         p.b->c.baseline, fit_range(*p.b), offset);
      };
      std::vector<PairWork> all;
      for (Work& a : work)
        for (Work& b : work) {
          if (&a == &b || a.dropped || b.dropped || a.c.discrete || b.c.discrete) continue;
          // The single effect that explains more goes first (its parameter is `fitted`).
          if (b.fit.chi2 < a.fit.chi2 || (b.fit.chi2 == a.fit.chi2 && &b < &a)) continue;
          PairWork p{&a, &b, {}, {}};
          fit_of(p, no_offset);
          // Run only a pair that would beat the best single effect decisively (its second
          // parameter paid for).
          if (p.fit.chi2 + 2.0 * ln_n + o.min_delta_bic <= best_single + ln_n) all.push_back(p);
        }
      std::sort(all.begin(), all.end(),
                [](const PairWork& x, const PairWork& y) { return x.fit.chi2 < y.fit.chi2; });
      if (static_cast<int>(all.size()) > o.pair_top) all.resize(o.pair_top);
      if (!all.empty())
        say(
            fmt::format("no single effect explains the data (best chi2 {:.1f}); {} pair(s) of "
                        "effects might (best: {} + {}, chi2 {:.1f} on the sum of their responses)",
                        best_single, all.size(), all.front().a->c.effect, all.front().b->c.effect,
                        all.front().fit.chi2));
      auto model_of = [&](const PairWork& p) {
        return p.b->c.apply(p.a->c.apply(base, p.fit.ta), p.fit.tb);
      };
      // Each pair is run at its fit, and once more where the run moves the fit (the sum's miss
      // at the run added to it as an offset); it stands where it was last run.
      std::vector<PairWork*> going;
      for (PairWork& p : all) going.push_back(&p);
      std::map<PairWork*, std::pair<double, double>> ran;  // where each was last run
      for (int run = 0; run < o.pair_runs && !going.empty(); ++run) {
        std::vector<ParticleModel> models;
        for (PairWork* p : going) models.push_back(model_of(*p));
        prefetch(models, o.repeats);
        std::vector<PairWork*> still;
        for (PairWork* p : going) {
          say(fmt::format("{} + {}: confirming at {} and {}", p->a->c.effect, p->b->c.effect,
                          p->a->c.format(p->fit.ta), p->b->c.format(p->fit.tb)));
          Values v;
          try {
            v = simulate(model_of(*p), o.repeats);
          } catch (const NumericalError& e) {
            say(fmt::format("{} + {}: the run failed: {}", p->a->c.effect, p->b->c.effect,
                            e.what()));
            if (ran.count(p)) std::tie(p->fit.ta, p->fit.tb) = ran[p];
            continue;
          }
          p->at_fit = v;
          const double ta = p->fit.ta, tb = p->fit.tb;
          ran[p] = {ta, tb};
          std::vector<double> offset(ms.size(), 0.0);
          for (size_t k = 0; k < ms.size(); ++k) {
            const std::string key = ms[k].key();
            offset[k] = v.at(key).mean - (p->a->s.value(key, ta) + p->b->s.value(key, tb) -
                                          p->b->s.value(key, p->b->c.baseline));
          }
          fit_of(*p, offset);
          const bool moved = std::abs(p->fit.ta - ta) > 0.25 * std::max(p->fit.sa, 1e-12) ||
                             std::abs(p->fit.tb - tb) > 0.25 * std::max(p->fit.sb, 1e-12);
          if (moved && run + 1 < o.pair_runs) {
            still.push_back(p);
          } else {
            p->fit.ta = ta;  // its chi2 is this run's; the uncertainties are the refit's
            p->fit.tb = tb;
          }
        }
        going = still;
      }
      for (PairWork& p : all)
        if (!p.at_fit.empty()) pairs.push_back(p);
    }
  }
  // All runs are made: every comparison weighs by the final pooled spread.
  d.baseline = compare(ms, pool.pooled(s0), 0);
  d.baseline_bic = d.baseline.bic;
  d.baseline_p = chi2_survival(d.baseline.chi2, n);
  for (Work& w : work) {
    if (w.dropped) continue;
    CandidateResult r;
    r.candidate = w.c;
    r.fitted = w.fit.theta;
    r.fitted_std = w.fit.sigma;
    r.fitted_lo = w.c.discrete ? r.fitted : w.fit.lo95;
    r.fitted_hi = w.c.discrete ? r.fitted : w.fit.hi95;
    // A surrogate's values keep the spread the fit gave them; a run's are pooled.
    r.comparison = compare(ms, w.source == "surrogate" ? w.at_fit : pool.pooled(w.at_fit), 1);
    r.chi2_source = w.source;
    r.chi2_at = w.at;
    r.delta_chi2 = d.baseline.chi2 - r.comparison.chi2;
    r.bic = r.comparison.chi2 + ln_n;
    const double span = w.c.hi - w.c.lo;
    r.at_bound =
        !w.c.discrete && (r.fitted <= w.c.lo + 0.01 * span || r.fitted >= w.c.hi - 0.01 * span);
    r.limit = w.limit;
    if (!w.c.discrete && !w.limit.empty()) {
      const auto [lo, hi] = fit_range(w);
      r.at_limit = (w.hi_ok < w.c.hi && r.fitted >= hi - 0.01 * span) ||
                   (w.lo_ok > w.c.lo && r.fitted <= lo + 0.01 * span);
    }
    r.plausible =
        w.c.discrete || (r.fitted >= w.c.lo && r.fitted <= w.c.hi && !r.at_bound && !r.at_limit);
    d.candidates.push_back(r);
  }
  for (const PairWork& p : pairs) {
    const EffectCandidate& ca = p.a->c;
    const EffectCandidate& cb = p.b->c;
    const PairFitResult& f = p.fit;
    CandidateResult r;
    r.candidate = ca;
    r.candidate.effect = ca.effect + "+" + cb.effect;
    const double tb = f.tb;
    r.candidate.apply = [ca, cb, tb](const ParticleModel& m, double v) {
      return cb.apply(ca.apply(m, v), tb);
    };
    r.fitted = f.ta;
    r.fitted_std = f.sa;
    r.fitted_lo = f.lo_a;
    r.fitted_hi = f.hi_a;
    r.with = CandidateResult::SecondEffect{cb, f.tb, f.sb, f.lo_b, f.hi_b};
    r.comparison = compare(ms, pool.pooled(p.at_fit), 2);
    r.chi2_source = "run";
    r.chi2_at = f.ta;
    r.delta_chi2 = d.baseline.chi2 - r.comparison.chi2;
    r.bic = r.comparison.chi2 + 2.0 * ln_n;
    auto inside = [](const EffectCandidate& c, double v) {
      const double span = c.hi - c.lo;
      return v > c.lo + 0.01 * span && v < c.hi - 0.01 * span;
    };
    r.at_bound = !inside(ca, f.ta) || !inside(cb, f.tb);
    r.plausible = !r.at_bound;
    d.candidates.push_back(r);
  }
  std::sort(d.candidates.begin(), d.candidates.end(),
            [](const CandidateResult& a, const CandidateResult& b) { return a.bic < b.bic; });
  // Posterior weights over baseline + candidates.
  double best_bic = d.baseline_bic;
  for (const auto& c : d.candidates) best_bic = std::min(best_bic, c.bic);
  double z = std::exp(-0.5 * (d.baseline_bic - best_bic));
  for (const auto& c : d.candidates) z += std::exp(-0.5 * (c.bic - best_bic));
  for (auto& c : d.candidates) c.weight = std::exp(-0.5 * (c.bic - best_bic)) / z;
  const double baseline_weight = std::exp(-0.5 * (d.baseline_bic - best_bic)) / z;

  d.consistent = true;
  d.confidence = baseline_weight;
  if (!d.candidates.empty()) {
    const CandidateResult& top = d.candidates.front();
    if (d.baseline_p < o.p_inconsistent && d.baseline_bic - top.bic >= o.min_delta_bic) {
      d.consistent = false;
      d.verdict = top.candidate.effect;
      d.confidence = top.weight;
      for (size_t i = 1; i < d.candidates.size(); ++i)
        if (d.candidates[i].bic - top.bic < 2.0)
          d.indistinguishable.push_back(d.candidates[i].candidate.effect);
      // Observables whose misfit the winner removes most.
      std::vector<std::pair<double, std::string>> gain;
      for (size_t i = 0; i < ms.size(); ++i) {
        const double z0 = d.baseline.observables[i].z, z1 = top.comparison.observables[i].z;
        gain.emplace_back(z0 * z0 - z1 * z1,
                          fmt::format("{}: z {:+.2f} -> {:+.2f}", observable_name(ms[i]), z0, z1));
      }
      std::sort(gain.rbegin(), gain.rend());
      for (size_t i = 0; i < gain.size() && i < 3; ++i)
        if (gain[i].first > 0) d.drivers.push_back(gain[i].second);
    }
  }

  // Which unmeasured rig setting would best separate the two leading explanations? Only asked
  // where the answer is needed (DiagnoseOptions::suggest_always).
  if (!o.suggest || o.suggest_max <= 0) {
    d.suggestion_note = "not simulated (switched off)";
  } else if (d.candidates.size() < 2) {
    d.suggestion_note = "not simulated: fewer than two candidates to tell apart";
  } else if (!o.suggest_always && d.consistent) {
    d.suggestion_note =
        "none needed: the model is consistent with the data (--suggest always simulates one)";
  } else if (!o.suggest_always && d.indistinguishable.empty() && d.confidence >= o.suggest_below) {
    d.suggestion_note = fmt::format(
        "none needed: the verdict is decisive (confidence {:.2f}, no other effect within 2 BIC "
        "units; --suggest always simulates one)",
        d.confidence);
  } else if (!o.suggest_always && d.indistinguishable.empty() && d.candidates[0].plausible) {
    // A runner-up pinned at its range's bound asks for an implausible strength (a red flag,
    // not an explanation): the verdict's weight among the plausible ones decides.
    double rest = 0.0;
    std::string pinned;
    for (size_t i = 1; i < d.candidates.size(); ++i) {
      const CandidateResult& c = d.candidates[i];
      // Only the top of the physical range counts: a fit stopped by failed runs (at_limit) or
      // pinned at "none" (the baseline's twin) is a rival like any other.
      const bool at_top = c.at_bound && c.fitted > 0.5 * (c.candidate.lo + c.candidate.hi);
      if (!at_top)
        rest += c.weight;
      else if (c.weight >= 0.01)
        pinned += fmt::format("{}{} at {}", pinned.empty() ? "" : ", ", c.candidate.effect,
                              c.candidate.format(c.fitted));
    }
    const double top = d.candidates[0].weight;
    const double among = top / (top + rest + baseline_weight);
    if (among >= o.suggest_below && !pinned.empty())
      d.suggestion_note = fmt::format(
          "none needed: the verdict is decisive among plausible effects (confidence {:.2f}, "
          "{:.2f} without {}, pinned at the bound of its plausible range; --suggest always "
          "simulates one)",
          d.confidence, among, pinned);
  }
  if (d.suggestion_note.empty()) {
    const CandidateResult& a = d.candidates[0];
    const CandidateResult& b = d.candidates[1];
    const ParticleModel ma = a.candidate.apply(base, a.fitted);
    const ParticleModel mb = b.candidate.apply(base, b.fitted);
    std::set<std::string> measured;
    std::map<std::string, double> rel_std;  // typical relative noise per quantity
    std::map<std::string, std::string> sample_of_rig;
    for (const auto& m : ms) {
      SimRequest r{m.rig, m.sample, m.setting};
      if (!r.settings.count("scale")) r.settings["scale"] = o.scale;
      measured.insert(r.key());
      if (m.value != 0)
        rel_std[m.quantity] = std::max(rel_std[m.quantity], m.std / std::abs(m.value));
      sample_of_rig.emplace(m.rig, m.sample);
    }
    std::vector<SimRequest> trial;
    for (const auto& rig : rig_catalogue()) {
      const std::string sample =
          sample_of_rig.count(rig.name) ? sample_of_rig[rig.name] : ms.front().sample;
      for (const auto& st : rig.settings) {
        std::vector<std::string> values = st.choices;
        if (st.key == "rpm") values = {"10", "15", "30"};
        if (!st.experimental || values.empty()) continue;
        for (const auto& v : values) {
          SimRequest r{rig.name, sample, parse_settings(rig, st.key + "=" + v, "suggest")};
          r.settings["scale"] = o.scale;
          if (!measured.count(r.key())) trial.push_back(r);
        }
      }
    }
    // Prefer rigs that were measured (their setup is known to work), then catalogue order.
    std::stable_sort(trial.begin(), trial.end(), [&](const SimRequest& x, const SimRequest& y) {
      return sample_of_rig.count(x.rig) > sample_of_rig.count(y.rig);
    });
    if (static_cast<int>(trial.size()) > o.suggest_max) trial.resize(o.suggest_max);
    try {
      std::vector<SimJob> jobs;
      for (const auto& r : trial) jobs.push_back({ma, r}), jobs.push_back({mb, r});
      sim.prefetch(jobs, o.repeats, o.seed);
    } catch (const std::exception&) {
      // Each trial is retried below on its own, and skipped if it fails.
    }
    for (const auto& r : trial) {
      say(fmt::format("suggestion: trying {} [{}]", r.rig, format_settings(r.settings)));
      SimValues va, vb;
      try {
        va = sim.simulate(ma, r, o.repeats, o.seed);
        vb = sim.simulate(mb, r, o.repeats, o.seed);
      } catch (const std::exception& e) {
        say(std::string("suggestion skipped: ") + e.what());
        continue;
      }
      for (const auto& [q, x] : va) {
        if (!vb.count(q)) continue;
        const double y = vb.at(q).mean;
        const double rel = rel_std.count(q) ? rel_std[q] : 0.02;
        const double sigma = std::hypot(rel * std::abs(x.mean), std::hypot(x.std, vb.at(q).std));
        if (sigma <= 0) continue;
        Suggestion s;
        s.rig = r.rig;
        s.sample = r.sample;
        auto settings = r.settings;
        settings.erase("scale");
        s.setting = format_settings(settings);
        s.quantity = q;
        s.separation = std::abs(x.mean - y) / sigma;
        s.between = a.candidate.effect + " vs " + b.candidate.effect;
        d.suggestions.push_back(s);
      }
    }
    std::sort(d.suggestions.begin(), d.suggestions.end(),
              [](const Suggestion& x, const Suggestion& y) { return x.separation > y.separation; });
    if (d.suggestions.empty())
      d.suggestion_note = trial.empty() ? "none: every experimental setting is measured already"
                                        : "none: no unmeasured setting could be simulated";
  }
  d.simulations = sim.runs() - runs0;
  return d;
}

std::string Diagnosis::summary() const {
  std::string s;
  s += fmt::format("baseline: chi2 = {:.2f} for {} observables (chi2/dof {:.2f}, p = {:.3g})\n",
                   baseline.chi2, baseline.observables.size(), baseline.chi2_per_dof, baseline_p);
  if (consistent) {
    s += fmt::format(
        "verdict: the model is consistent with the data; no effect improves it decisively "
        "(baseline weight {:.2f})\n",
        confidence);
    if (screen_only)
      s += "  (the baseline was consistent after the screen, so the candidates were screened "
           "only: their chi2 is the response surrogate's or a one-repeat screening run's)\n";
  } else {
    const CandidateResult& t = candidates.front();
    if (!t.with) {
      s += fmt::format("verdict: missing effect '{}' ({} = {} +/- {:.2g}{}), confidence {:.2f}\n",
                       verdict, t.candidate.parameter, t.candidate.format(t.fitted), t.fitted_std,
                       t.candidate.discrete ? "" : "; 95 %: " + interval_text(t), confidence);
    } else {
      const EffectCandidate& w = t.with->candidate;
      const std::string first = t.candidate.effect.substr(0, t.candidate.effect.find('+'));
      s += fmt::format(
          "verdict: two missing effects, '{}' ({} = {} +/- {:.2g}; 95 %: {}) and '{}' ({} = {} "
          "+/- {:.2g}; 95 %: {:.3g} to {:.3g}), confidence {:.2f}; no single effect explains the "
          "data\n",
          first, t.candidate.parameter, t.candidate.format(t.fitted), t.fitted_std,
          interval_text(t), w.effect, w.parameter, w.format(t.with->fitted), t.with->std,
          t.with->lo, t.with->hi, confidence);
    }
    if (t.at_limit)
      s += "  warning: the fitted value is pinned at the edge of what the rigs could measure (" +
           t.limit + "): the strength may be larger than fitted\n";
    else if (!t.plausible)
      s += "  warning: the fitted value is pinned at the edge of its physical range: the effect "
           "it stands for may be the wrong one\n";
    for (const auto& dr : drivers) s += "  driven by " + dr + "\n";
    if (!indistinguishable.empty()) {
      s += "  indistinguishable on these data from:";
      for (const auto& e : indistinguishable) s += " " + e;
      s += "\n";
    }
  }
  if (!suggestions.empty()) {
    const Suggestion& g = suggestions.front();
    s += fmt::format("next measurement: {} sample {}{} {} separates {} by {:.1f} sigma\n", g.rig,
                     g.sample, g.setting.empty() ? "" : " [" + g.setting + "]", g.quantity,
                     g.between, g.separation);
  } else if (!suggestion_note.empty()) {
    s += "next measurement: " + suggestion_note + "\n";
  }
  return s;
}

}  // namespace clumpkit::calibrate
