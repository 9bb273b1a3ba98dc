#pragma once
/// The diagnosis's response surrogates (diagnosis.cpp): how the simulated observables change
/// with one candidate effect's strength, fitted through the rig runs made so far, and the fits
/// of that strength (alone, or two effects at once) to the measurements, with their
/// uncertainties. No simulation happens here.
#include <limits>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "clumpkit/calibrate/comparison.hpp"

namespace clumpkit::calibrate {

/// Simulated observables keyed by Measurement::key().
using Values = std::map<std::string, SimulatedValue>;

/// Response surrogate of one candidate through its simulated points (theta, values): a line
/// through two points, a least-squares parabola through three or more, continued as a straight
/// line (its tangent) beyond the points. Each point is a mean of a few noisy repeats, so the
/// surrogate smooths rather than interpolates: a piecewise-linear interpolant takes its slope
/// from the two nearest points, and two nearby refinement points give a slope that is mostly
/// seed noise (and with it a fitted uncertainty several times too small).
/// A rig's response over a candidate's whole range is often no parabola (the packing falls
/// fast with the first bit of cohesion, then levels off; a heap's angle rises slowly, then
/// steeply): where the parabola misses its points by more than their seed noise (a lack-of-fit
/// chi2 test at 1 %), the points farthest from the `focus` (where the fit is being made) are
/// dropped, down to three, so the surrogate is local where it must be and smooth where it can be.
class Surrogate {
 private:
  struct Poly {
    double mid = 0, half = 1, a = 0, b = 0, c = 0;  ///< a + b x + c x^2, x = (t - mid) / half
    double lo = 0, hi = 0;                          ///< span of the points it follows
  };

 public:
  /// A fit misses its points by more than their seed noise when a miss this large has a
  /// probability below this (chi2 test).
  static constexpr double kLackOfFit = 0.01;
  std::vector<std::pair<double, Values>> points;  ///< sorted by theta

  /// Adds (or replaces) the point at `theta`.
  void add(double theta, Values v);
  /// Where the next fit is made, and the pooled seed-to-seed spread of one run per observable
  /// (the noise the lack-of-fit test weighs the points' misses by), pooled in the families of
  /// `pool` (none: each observable its own).
  void aim(double theta, const Values& pooled, const SpreadPool* pool = nullptr);
  /// The surrogate's mean of observable `key` at `theta`.
  double value(const std::string& key, double theta) const;
  /// The surrogate's curve of one observable, evaluated like value() without looking the
  /// observable up: a fit's grid evaluates it thousands of times. A copy, valid until the
  /// surrogate's points or aim change.
  class Curve {
   public:
    double operator()(double theta) const;

   private:
    friend class Surrogate;
    explicit Curve(const Poly& p) : p_(p) {}
    Poly p_;
  };
  Curve curve(const std::string& key) const { return Curve(poly(key)); }
  /// A copy whose points' means are redrawn within their seed noise (one run's variance:
  /// scatter_var, else, where the surrogate was not aimed, the point's own spread; std^2 / n
  /// for a mean of n repeats). Fitted again, it shows how far the fit moves with the surrogate's
  /// own noise.
  Surrogate redrawn(std::mt19937_64& rng) const;
  /// Variance of a simulated mean through the surrogate, averaged over its points: each point's
  /// own seed scatter (std^2/n) where it has repeats, the pooled per-run variance `run_var` for
  /// a single-run (screening) point; never below the baseline's `run_var / base_n`. Heaps with
  /// more rolling friction scatter more than the baseline's (tiny scale: 2-4 deg against 1.6),
  /// so the baseline's scatter alone understated the fitted uncertainty. Where the points
  /// scatter about a smooth curve by more than `run_var` (scatter_var), by that scatter.
  double noise_var(const std::string& key, double run_var, int base_n) const;
  /// One run's variance of observable `key` as the surrogate weighs its points: the pooled one
  /// it was aimed with, or, where neighbouring points scatter about a smooth curve by
  /// significantly more (a chi2 test at 5 %), that scatter (as a multiple of the pooled
  /// variance, the same for the observables of one pooling family). The scatter is measured
  /// from pseudo-residuals (each point against the straight line through its two neighbours, a
  /// difference-based estimate that a linear trend does not bias) of the points close together,
  /// as refinement runs are (three in a row within a quarter of all the points' span, where
  /// curvature adds little), over the family's observables. The pooled spread need not be all
  /// of a mean's scatter: it is pooled over settings that scatter differently, each from a few
  /// two-repeat spreads. Session 45's mixture (tiny scale, pill A with tablet D) pooled 1.8 deg
  /// over three plates (0.97 deg on galvanized steel, 2.1 on ABS, 2.3 on organic glass) where
  /// six more seeds on ABS gave 3.1; four refinement means on ABS within 0.035 of A's share
  /// then spread over 8 deg, and, taken as signal, gave a local slope of 270 deg per unit and a
  /// stated uncertainty of the fit 7 times too small. 0 if the surrogate was not aimed.
  double scatter_var(const std::string& key) const;

 private:
  /// (theta, mean, repeats) of the points, for one observable.
  struct Pt {
    double t, y;
    int n;
  };
  /// Points closer together than this share of all the points' span count as neighbours for
  /// scatter_var.
  static constexpr double kNeighbourSpan = 0.25;
  /// The points' scatter replaces the pooled run variance where so large a scatter has a
  /// probability below this with the pooled one (chi2 test).
  static constexpr double kExcessScatter = 0.05;
  mutable std::map<std::string, Poly> coef;
  /// scatter_var's factor on the pooled variance per family, computed once per set of points
  /// (a redrawn copy keeps the original's: the redraw's own noise must not be counted twice).
  mutable std::map<std::string, double> scatter;
  double focus = std::numeric_limits<double>::quiet_NaN();
  std::map<std::string, double> run_var;
  std::map<std::string, std::string> family;  ///< observable key -> its pooling family

  /// Lack of fit of `p` at the points, in units of their seed noise (`var`: one run's
  /// variance), as the probability of a miss this large from noise alone.
  static double fits_within_noise(const Poly& p, const std::vector<Pt>& pts, double var);
  /// The least-squares line or parabola through the points (`var`: one run's seed variance,
  /// 0 if unknown).
  static Poly fit(const std::vector<Pt>& pts, double var);
  /// The fit of observable `key`, made local around `focus` where one parabola misses.
  const Poly& poly(const std::string& key) const;
};

/// Variance of each measurement's difference from the surrogate: the lab's and the
/// simulations' (the same for every theta of one fit).
std::vector<double> fit_variances(const std::vector<Measurement>& ms, const Values& base,
                                  const Surrogate& s);

/// chi2 of the measurements against the surrogate at `theta`, with the variances `var`.
double chi2_of(const std::vector<Measurement>& ms, const std::vector<double>& var,
               const Surrogate& s, double theta);
/// The same with the surrogate's curves of the measurements (`curves[i]` that of `ms[i]`).
double chi2_of(const std::vector<Measurement>& ms, const std::vector<double>& var,
               const std::vector<Surrogate::Curve>& curves, double theta);

/// One candidate's strength fitted on its surrogate.
struct Fit {
  double theta = 0, chi2 = 0, sigma = 0;
  double lo95 = 0, hi95 = 0;  ///< Delta chi2 = 4 on the surrogate (asymmetric where it levels off)
};

/// The least chi2 over [lo, hi] (a grid of 2 000 steps); sigma: half the Delta chi2 = 1
/// interval, an open side extending to the range's bound, combined with the spread of the fit
/// over surrogates redrawn within their points' seed noise (`redraws` of them, seeded: the same
/// points give the same sigma). The Delta chi2 interval takes the curve as exact; a curve
/// through a few noisy means has an uncertain slope. On the stand-in with noisy runs the truth
/// fell within 1 stated sigma in 31 of 40 trials with the redraws, 26 without (nominal 27). The
/// 95 % interval widens in proportion. The redraws do not widen sigma where the points' assumed
/// noise is too small: session 44's mixture (one heap's refinement means rose 4.4 deg over 0.03
/// of A's share, the fit 0.667 +/- 0.008 for a truth of 0.7) needed Surrogate::scatter_var.
Fit fit_surrogate(const std::vector<Measurement>& ms, const Values& base, const Surrogate& s,
                  double lo, double hi, int redraws = 32);

/// Two continuous candidates at once, on the sum of their one-effect surrogates: the responses
/// to a and to b add (each surrogate's change from its own baseline), plus `offset`, what a run
/// of the pair showed the sum to miss (the interaction). chi2 on a grid over both ranges; each
/// parameter's uncertainty from its profile (the least chi2 over the other).
struct PairFitResult {
  double ta = 0, tb = 0, chi2 = std::numeric_limits<double>::infinity();
  double sa = 0, sb = 0, lo_a = 0, hi_a = 0, lo_b = 0, hi_b = 0;
};

PairFitResult fit_pair(const std::vector<Measurement>& ms, const Values& pooled, const Surrogate& a,
                       double base_a, std::pair<double, double> range_a, const Surrogate& b,
                       double base_b, std::pair<double, double> range_b,
                       const std::vector<double>& offset);

}  // namespace clumpkit::calibrate
