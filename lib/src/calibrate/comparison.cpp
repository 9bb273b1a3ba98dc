#include "clumpkit/calibrate/comparison.hpp"

#include <cmath>
#include <stdexcept>

namespace clumpkit {

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

}  // namespace

double chi2_survival(double x, int dof) {
  return gamma_q(0.5 * dof, 0.5 * x);
}

SimulatedValue summarize(const std::vector<double>& r) {
  SimulatedValue s;
  s.n = static_cast<int>(r.size());
  if (r.empty()) return s;
  for (double v : r) s.mean += v;
  s.mean /= static_cast<double>(r.size());
  if (r.size() > 1) {
    double var = 0;
    for (double v : r) var += (v - s.mean) * (v - s.mean);
    s.std = std::sqrt(var / static_cast<double>(r.size() - 1));
  }
  return s;
}

SpreadPool::SpreadPool(const std::vector<Measurement>& measurements) {
  for (const Measurement& m : measurements)
    family_[m.key()] = m.rig + "|" + m.sample + "|" + m.quantity;
}

const std::string& SpreadPool::family(const std::string& key) const {
  auto it = family_.find(key);
  return it == family_.end() ? key : it->second;
}

void SpreadPool::add(const std::map<std::string, SimulatedValue>& values) {
  for (const auto& [key, v] : values) {
    if (v.n < 2 || !std::isfinite(v.std)) continue;
    auto& [sum, dof] = acc_[family(key)];
    sum += (v.n - 1) * v.std * v.std;
    dof += v.n - 1;
  }
}

std::map<std::string, SimulatedValue> SpreadPool::pooled(
    std::map<std::string, SimulatedValue> values) const {
  for (auto& [key, v] : values) {
    auto it = acc_.find(family(key));
    if (it != acc_.end() && it->second.second > 0)
      v.std = std::sqrt(it->second.first / it->second.second);
  }
  return values;
}

int SpreadPool::dof(const std::string& key) const {
  auto it = acc_.find(family(key));
  return it == acc_.end() ? 0 : it->second.second;
}

Comparison compare(const std::vector<Measurement>& measured,
                   const std::map<std::string, SimulatedValue>& simulated, int k) {
  Comparison c;
  for (const Measurement& m : measured) {
    auto it = simulated.find(m.key());
    if (it == simulated.end()) throw std::invalid_argument("compare: no simulation for " + m.key());
    ObservableComparison o;
    o.measured = m;
    o.simulated = it->second;
    o.difference = o.simulated.mean - m.value;
    const double var =
        m.std * m.std / m.n +
        (o.simulated.n > 0 ? o.simulated.std * o.simulated.std / o.simulated.n : 0.0);
    o.sigma = std::sqrt(var);
    o.z = o.difference / o.sigma;
    o.rel_error = m.value != 0.0 ? o.difference / std::abs(m.value) : 0.0;
    o.pass = std::abs(o.z) <= 2.0;
    c.chi2 += o.z * o.z;
    c.observables.push_back(o);
  }
  const int n = static_cast<int>(measured.size());
  c.dof = std::max(1, n - k);
  c.chi2_per_dof = c.chi2 / c.dof;
  c.bic = c.chi2 + k * std::log(std::max(1, n));
  c.aic = c.chi2 + 2.0 * k;
  return c;
}

}  // namespace clumpkit
