#pragma once
/// Which physical effect is the model missing? For every candidate effect (effects.hpp) the
/// diagnosis measures its local sensitivity with one perturbed simulation per rig setting
/// (common random numbers: the same seeds as the baseline), fits its strength to the residuals
/// with the measured noise as weights, refines the fit with real simulations at the fitted value
/// (secant steps on the response), and ranks the effects by BIC = chi2 + k ln N (k = 1 parameter
/// per effect; the baseline has k = 0). Discrete effects (sphere count, rolling model) are
/// simulated at each level.
///
/// A verdict is given only when the baseline is inconsistent with the data (chi2 p-value below
/// `p_inconsistent`) and the best effect improves the BIC by at least `min_delta_bic`; otherwise
/// the report says that the model is consistent with the data.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "clumpkit/calibrate/comparison.hpp"
#include "clumpkit/calibrate/effects.hpp"
#include "clumpkit/calibrate/simulator.hpp"

namespace clumpkit::calibrate {

struct DiagnoseOptions {
  std::string scale = "mini";
  int repeats = 2;  ///< repeats of the baseline, the refinements and the confirmations
  /// Repeats of the first phase's probes and discrete levels (a screen: the leaders are
  /// simulated again at `repeats` when refined). Their variance comes from the spread pooled
  /// over every variant with repeats.
  int screen_repeats = 1;
  std::uint64_t seed = 1;
  std::vector<std::string> effects;  ///< empty: the whole catalogue
  /// The simulator's engine ("clumpkit" or "liggghts"). LIGGGHTS has no standard rolling model
  /// and runs it as CDT, so there a baseline with the standard model is not screened against
  /// CDT (the same physics), nor a CDT baseline against the standard model.
  std::string engine = "clumpkit";
  int refinements = 2;  ///< real-run refinement steps for the leading candidates
  int refine_top = 3;   ///< how many leading candidates are refined
  /// Further steps for the candidate whose fit leads, while its fit still moves by more than a
  /// quarter of its uncertainty (a response far from a parabola converges in more steps); only
  /// where the baseline is inconsistent with the data (p < p_inconsistent).
  int extra_refinements = 2;
  /// Runs (every repeat) at the far end of the leading candidate's 95 % interval where it
  /// reaches past the strengths simulated for it (CandidateResult::interval_past_runs), at
  /// most this many, after the ranking, wherever the candidates are refined. Past the runs
  /// the interval rests on the surrogate's straight continuation, too steep where the
  /// response levels off. 0: none (the interval is then only marked).
  int end_runs = 2;
  double min_delta_bic = 6.0;  ///< "strong" evidence (Kass & Raftery)
  double p_inconsistent = 0.01;
  /// A baseline whose chi2 survival after the screen is at least this gets no refinement or
  /// confirmation runs (no verdict is possible; Diagnosis::screen_only). 1.01: never.
  double p_screen_only = 0.05;
  /// A continuous candidate whose response surrogate puts its chi2 at the fitted value this far
  /// above the best chi2 any real run has reached gets no confirmation run: its chi2 is the
  /// surrogate's (CandidateResult::chi2_source). 25 is a BIC weight below e^-12 of the leader's.
  double confirm_margin = 25.0;
  /// Fit pairs of continuous effects where no single effect explains the data (a run of the
  /// best single one has p < p_inconsistent): the `pair_top` best pairs on the sum of their
  /// responses that would beat the best single effect by min_delta_bic are run (at most
  /// `pair_runs` times each) and ranked with two parameters (BIC k = 2).
  /// Pairs need at least this many observables: with fewer, a pair's chi2 has two degrees of
  /// freedom or less, and a noisy draw is fitted as a second effect (the noisy rolling-friction
  /// test on three heaps ranked rolling + wall friction first in 2 of 40 draws).
  bool pairs = true;
  int pair_min_observables = 5;
  int pair_top = 3;
  int pair_runs = 2;
  bool suggest = true;  ///< simulate unmeasured settings to suggest a measurement
  /// Simulate them even when no measurement is needed: the model is consistent with the data,
  /// or the verdict is decisive (confidence >= suggest_below and no effect indistinguishable).
  /// The suggestion's runs (each trial setting for both leading models, with every repeat)
  /// cost as much as a candidate's screening and confirmation together.
  bool suggest_always = false;
  double suggest_below = 0.9;  ///< a verdict less confident than this gets a suggestion
  int suggest_max = 4;         ///< at most this many settings tried
  std::function<void(const std::string&)> progress;
};

struct CandidateResult {
  EffectCandidate candidate;
  double fitted = 0.0;      ///< parameter value (candidate.unit)
  double fitted_std = 0.0;  ///< 1-sigma uncertainty from the fit's curvature (0: discrete)
  /// The 95 % interval where chi2 on the response surrogate is within 4 of its minimum:
  /// asymmetric where a response levels off (fitted_std, the Delta chi2 = 1 half-width, is then
  /// short on the flat side); an open side reaches the fit's range. Discrete: both = fitted.
  double fitted_lo = 0.0, fitted_hi = 0.0;
  /// The span of the strengths simulated for this candidate (the baseline's included). Where
  /// the 95 % interval reaches past it, the response there is the surrogate's straight
  /// continuation, not a run: a response that levels off past the last run (cohesion) makes
  /// that side of the interval too short. Equal when not known (discrete, pairs).
  double runs_lo = 0.0, runs_hi = 0.0;
  /// Runs made at the far end of this (leading) candidate's interval after the ranking
  /// (DiagnoseOptions::end_runs); they can only widen fitted_lo..fitted_hi and fitted_std.
  int end_runs = 0;
  /// Whether the 95 % interval reaches past the simulated span by more than 5 % of it
  /// (interval_text marks it "*").
  bool interval_past_runs() const;
  Comparison comparison;  ///< against the data, at `chi2_at` (see chi2_source)
  /// How `comparison` was obtained: "run" (a simulation at `fitted`), "screen" (a discrete
  /// level's one-repeat screening run, Diagnosis::screen_only), "nearest_run" (the
  /// simulation at `chi2_at`, within a quarter of the fitted uncertainty of `fitted`: Delta chi2
  /// below ~0.06 by the fit's own curvature) or "surrogate" (no run: the response surrogate
  /// puts this candidate at least DiagnoseOptions::confirm_margin above the best run, or
  /// Diagnosis::screen_only).
  std::string chi2_source = "run";
  double chi2_at = 0.0;
  double delta_chi2 = 0.0;  ///< baseline chi2 - this chi2
  double bic = 0.0;
  bool plausible = true;  ///< fitted value inside the physical range, not pinned at a bound
  bool at_bound = false;
  /// Where a run of this candidate failed, and why (empty if none did): the rigs could not
  /// measure there, so the fit is kept short of it. at_limit: the fit is pinned against it.
  std::string limit;
  bool at_limit = false;
  double weight = 0.0;  ///< posterior weight among baseline + candidates (BIC)
  /// A pair of effects (DiagnoseOptions::pairs): candidate.effect is "first+second", the rest
  /// of `candidate` and `fitted` are the first's, `with` is the second's fit; candidate.apply
  /// adds both. Empty: one effect.
  struct SecondEffect {
    EffectCandidate candidate;
    double fitted = 0.0, std = 0.0, lo = 0.0, hi = 0.0;  ///< value, 1 sigma, 95 % interval
  };
  std::optional<SecondEffect> with;
};

struct Suggestion {
  std::string rig, sample, setting, quantity;
  double separation = 0.0;  ///< |prediction A - prediction B| / expected measurement std
  std::string between;      ///< "effect A vs effect B"
};

struct Diagnosis {
  Comparison baseline;
  double baseline_bic = 0.0;
  double baseline_p = 1.0;                  ///< chi2 survival probability of the baseline
  std::vector<CandidateResult> candidates;  ///< best first
  std::vector<std::string> skipped;         ///< effects not tried, with the reason
  bool consistent = true;                   ///< no verdict: the baseline explains the data
  /// The baseline explained the data after the screen (p >= p_screen_only): no candidate was
  /// refined or confirmed (their chi2_source: "surrogate" or "screen").
  bool screen_only = false;
  std::string verdict;               ///< the winning effect, empty when consistent
  double confidence = 0.0;           ///< posterior weight of the verdict (or of the baseline)
  std::vector<std::string> drivers;  ///< observables that drive the verdict
  std::vector<std::string> indistinguishable;  ///< effects within 2 BIC units of the best
  std::vector<Suggestion> suggestions;         ///< best first
  std::string suggestion_note;  ///< why no measurement was suggested (empty when one was)
  long simulations = 0;         ///< rig runs made (not served by the cache)
  /// The thresholds the verdict was given by (DiagnoseOptions), for the summary's words.
  double p_inconsistent = 0.01, p_screen_only = 0.05, min_delta_bic = 6.0;
  std::string summary() const;  ///< the verdict in words
};

Diagnosis diagnose(const ParticleModel& baseline, const std::vector<Measurement>& measurements,
                   Simulator& simulator, const DiagnoseOptions& options);

/// Where a candidate's chi2 comes from, in words: "run", "run at <value>" or "surrogate".
std::string chi2_source_text(const CandidateResult& r);
/// "0.17 to 0.23" (the 95 % interval, in the parameter's unit), "-" for a discrete candidate;
/// "0.17 to 0.23*" where it reaches past the candidate's runs (interval_past_runs).
std::string interval_text(const CandidateResult& r);
/// The footnote of a candidates table with a "*" interval.
inline constexpr const char* kIntervalPastRunsNote =
    "* 95 % interval past the strengths simulated for the candidate: there the response is the "
    "surrogate's straight continuation, not a run";
/// The candidate's parameter, and a pair's second one with its value: "mu_r (with cohesion:
/// SJKR energy density = 8750 J/m^3)".
std::string parameter_text(const CandidateResult& r);

}  // namespace clumpkit::calibrate
