#include "surrogate.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace clumpkit::calibrate {

void Surrogate::add(double theta, Values v) {
  for (auto& p : points)
    if (p.first == theta) {
      p.second = std::move(v);
      coef.clear();
      scatter.clear();
      return;
    }
  points.emplace_back(theta, std::move(v));
  std::sort(points.begin(), points.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  coef.clear();
  scatter.clear();
}

void Surrogate::aim(double theta, const Values& pooled, const SpreadPool* pool) {
  focus = theta;
  run_var.clear();
  family.clear();
  for (const auto& [k, v] : pooled) {
    if (v.n >= 2 && std::isfinite(v.std) && v.std > 0) run_var[k] = v.std * v.std;
    family[k] = pool ? pool->family(k) : k;
  }
  coef.clear();
  scatter.clear();
}

double Surrogate::scatter_var(const std::string& key) const {
  const auto rv = run_var.find(key);
  if (rv == run_var.end()) return 0.0;
  auto family_of = [&](const std::string& k) -> const std::string& {
    const auto f = family.find(k);
    return f == family.end() ? k : f->second;
  };
  const std::string& fam = family_of(key);
  auto known = scatter.find(fam);
  if (known == scatter.end()) {
    double sum = 0.0;  // pseudo-residuals squared, each in units of its observable's run variance
    int k = 0;
    const double span = points.empty() ? 0.0 : points.back().first - points.front().first;
    for (const auto& [other, var] : run_var) {
      if (family_of(other) != fam) continue;
      for (size_t i = 1; i + 1 < points.size(); ++i) {
        const double t0 = points[i - 1].first, t1 = points[i].first, t2 = points[i + 1].first;
        if (t2 - t0 > kNeighbourSpan * span) continue;
        const SimulatedValue& y0 = points[i - 1].second.at(other);
        const SimulatedValue& y1 = points[i].second.at(other);
        const SimulatedValue& y2 = points[i + 1].second.at(other);
        const double b = (t1 - t0) / (t2 - t0), a = 1.0 - b;
        const double e = a * y0.mean + b * y2.mean - y1.mean;
        sum += e * e / var /
               (a * a / std::max(1, y0.n) + b * b / std::max(1, y2.n) + 1.0 / std::max(1, y1.n));
        ++k;
      }
    }
    const double factor = k > 0 && chi2_survival(sum, k) < kExcessScatter ? sum / k : 1.0;
    known = scatter.emplace(fam, factor).first;
  }
  return known->second * rv->second;
}

double Surrogate::value(const std::string& key, double theta) const {
  return curve(key)(theta);
}

double Surrogate::Curve::operator()(double theta) const {
  const Poly& c = p_;
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

Surrogate Surrogate::redrawn(std::mt19937_64& rng) const {
  if (!points.empty())
    for (const auto& [key, x] : points.front().second) scatter_var(key);
  Surrogate r = *this;  // with this surrogate's scatter_var
  r.coef.clear();
  std::normal_distribution<double> g(0.0, 1.0);
  for (auto& [t, v] : r.points)
    for (auto& [key, x] : v) {
      const double aimed = scatter_var(key);
      const double var = aimed > 0.0 ? aimed : x.n >= 2 ? x.std * x.std : 0.0;
      const double draw = g(rng);  // drawn for every value: the stream does not depend on var
      if (var > 0.0) x.mean += draw * std::sqrt(var / std::max(1, x.n));
    }
  return r;
}

double Surrogate::noise_var(const std::string& key, double run_var, int base_n) const {
  run_var = std::max(run_var, scatter_var(key));
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

double Surrogate::fits_within_noise(const Poly& p, const std::vector<Pt>& pts, double var) {
  double miss = 0.0;
  for (const Pt& q : pts) {
    const double x = (q.t - p.mid) / p.half, r = p.a + x * (p.b + x * p.c) - q.y;
    miss += r * r * std::max(1, q.n) / var;
  }
  const int dof = static_cast<int>(pts.size()) - (p.c != 0.0 ? 3 : 2);
  return dof > 0 ? chi2_survival(miss, dof) : 1.0;
}

Surrogate::Poly Surrogate::fit(const std::vector<Pt>& pts, double var) {
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

const Surrogate::Poly& Surrogate::poly(const std::string& key) const {
  auto it = coef.find(key);
  if (it != coef.end()) return it->second;
  std::vector<Pt> pts;
  for (const auto& [t, v] : points) pts.push_back({t, v.at(key).mean, v.at(key).n});
  const double var = scatter_var(key);
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

std::vector<double> fit_variances(const std::vector<Measurement>& ms, const Values& base,
                                  const Surrogate& s) {
  std::vector<double> var;
  for (const auto& m : ms) {
    const SimulatedValue& b = base.at(m.key());
    var.push_back(m.std * m.std / m.n + s.noise_var(m.key(), b.std * b.std, b.n));
  }
  return var;
}

namespace {

std::vector<Surrogate::Curve> curves_of(const std::vector<Measurement>& ms, const Surrogate& s) {
  std::vector<Surrogate::Curve> curves;
  curves.reserve(ms.size());
  for (const auto& m : ms) curves.push_back(s.curve(m.key()));
  return curves;
}

}  // namespace

double chi2_of(const std::vector<Measurement>& ms, const std::vector<double>& var,
               const std::vector<Surrogate::Curve>& curves, double theta) {
  double chi2 = 0;
  for (size_t i = 0; i < ms.size(); ++i) {
    const double d = curves[i](theta) - ms[i].value;
    chi2 += d * d / var[i];
  }
  return chi2;
}

double chi2_of(const std::vector<Measurement>& ms, const std::vector<double>& var,
               const Surrogate& s, double theta) {
  return chi2_of(ms, var, curves_of(ms, s), theta);
}

Fit fit_surrogate(const std::vector<Measurement>& ms, const Values& base, const Surrogate& s,
                  double lo, double hi, int redraws) {
  const int n = redraws > 0 ? 2000 : 400;
  std::vector<double> th(n + 1), c(n + 1);
  Fit f;
  f.chi2 = std::numeric_limits<double>::infinity();
  int best = 0;
  const std::vector<double> var = fit_variances(ms, base, s);
  const std::vector<Surrogate::Curve> curves = curves_of(ms, s);
  for (int i = 0; i <= n; ++i) {
    th[i] = lo + (hi - lo) * i / n;
    c[i] = chi2_of(ms, var, curves, th[i]);
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
  if (redraws < 2 || s.points.size() < 2) return f;
  // The surrogate's own noise: the fit on redrawn surrogates (a coarser grid), its spread added
  // to sigma in quadrature.
  std::mt19937_64 rng(0x5eed5eedULL + s.points.size());
  double sum = 0.0, sum2 = 0.0;
  for (int r = 0; r < redraws; ++r) {
    const Fit fr = fit_surrogate(ms, base, s.redrawn(rng), lo, hi, 0);
    sum += fr.theta;
    sum2 += fr.theta * fr.theta;
  }
  const double mean = sum / redraws;
  const double spread =
      std::sqrt(std::max(0.0, sum2 / redraws - mean * mean) * redraws / (redraws - 1.0));
  const double sigma = std::hypot(f.sigma, spread);
  if (f.sigma > 0.0) {
    const double k = sigma / f.sigma;
    f.lo95 = std::max(lo, f.theta - k * (f.theta - f.lo95));
    f.hi95 = std::min(hi, f.theta + k * (f.hi95 - f.theta));
  } else {
    f.lo95 = std::max(lo, f.theta - 2.0 * sigma);
    f.hi95 = std::min(hi, f.theta + 2.0 * sigma);
  }
  f.sigma = sigma;
  return f;
}

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
    const Surrogate::Curve ca = a.curve(key), cb = b.curve(key);
    const double a0 = ca(base_a), b0 = cb(base_b);
    for (int i = 0; i <= kGrid; ++i) {
      da[i * n + k] = ca(axis(range_a, i)) - a0;
      db[i * n + k] = cb(axis(range_b, i)) - b0;
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

}  // namespace clumpkit::calibrate
