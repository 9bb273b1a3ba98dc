#pragma once
/// Measured against simulated observables: z-scores, chi-square, information criteria.
/// z = (simulated - measured) / sqrt(s_meas^2 / n_meas + s_sim^2 / n_sim): the difference of two
/// means over its standard error, with both standard deviations from repeats (the lab's, and the
/// simulation's repeats with different seeds). A single simulation run (n_sim = 1, no spread) adds
/// nothing to the denominator.
#include <map>
#include <string>
#include <vector>

#include "clumpkit/calibrate/measurements.hpp"

namespace clumpkit {

/// Simulated observable: mean and standard deviation over `n` repeats (different seeds).
struct SimulatedValue {
  double mean = 0.0;
  double std = 0.0;
  int n = 1;
};

struct ObservableComparison {
  Measurement measured;
  SimulatedValue simulated;
  double difference = 0.0;  ///< simulated - measured, canonical unit
  double sigma = 0.0;       ///< combined standard error
  double z = 0.0;
  double rel_error = 0.0;  ///< difference / |measured|
  bool pass = false;       ///< |z| <= 2
};

struct Comparison {
  std::vector<ObservableComparison> observables;
  double chi2 = 0.0;
  int dof = 0;  ///< observables - fitted parameters (at least 1)
  double chi2_per_dof = 0.0;
  double bic = 0.0;  ///< chi2 + k ln N (Gaussian likelihood, constants dropped)
  double aic = 0.0;  ///< chi2 + 2 k
};

/// `simulated` is keyed by Measurement::key(). Throws std::invalid_argument if one is missing
/// (a programming error: the caller simulates what the measurements need).
Comparison compare(const std::vector<Measurement>& measured,
                   const std::map<std::string, SimulatedValue>& simulated,
                   int fitted_parameters = 0);

/// The seed-to-seed spread of each observable pooled over several simulated models (the versions
/// of a chain, the variants of a diagnosis) and over the settings of one rig quantity (the angle
/// of repose on three plates): s^2 = sum (n_i - 1) s_i^2 / sum (n_i - 1). Two repeats of one model
/// give a spread with one degree of freedom, which is often several times too small and then
/// turns seed noise into a spurious misfit; the scatter of a rig's quantity changes little between
/// nearby models and settings, so pooling estimates it far better.
class SpreadPool {
 public:
  SpreadPool() = default;
  /// Pools each measurement's observable with the others of its rig, sample and quantity.
  explicit SpreadPool(const std::vector<Measurement>& measurements);
  /// Adds one model's values (each observable's spread from its repeats). The caller adds each
  /// distinct model once.
  void add(const std::map<std::string, SimulatedValue>& values);
  /// `values` with each spread replaced by the pooled one where the pool knows the observable.
  std::map<std::string, SimulatedValue> pooled(std::map<std::string, SimulatedValue> values) const;
  /// Degrees of freedom behind the pooled spread of observable `key` (0: unknown).
  int dof(const std::string& key) const;
  /// The pooling family of observable `key` (rig|sample|quantity; the key itself if unknown).
  const std::string& family(const std::string& key) const;

 private:
  std::map<std::string, std::string> family_;          ///< observable key -> pooling family
  std::map<std::string, std::pair<double, int>> acc_;  ///< per family: sum (n-1) s^2, sum (n-1)
};

/// Mean and sample standard deviation of repeats.
SimulatedValue summarize(const std::vector<double>& repeats);

/// Survival function of the chi-square distribution, P(X >= x) with `dof` degrees of freedom.
double chi2_survival(double x, int dof);

}  // namespace clumpkit
