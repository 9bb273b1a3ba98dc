#pragma once
/// The candidate effects a diagnosis tries (SPEC §8), each with one parameter, its plausible
/// physical range and how to switch it on in a model. An effect already on is tried at a changed
/// strength ("held at a baseline"); an absent one is switched on.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "clumpkit/rigs/model.hpp"

namespace clumpkit::calibrate {

struct EffectCandidate {
  std::string effect;         ///< SPEC §8 id
  std::string parameter;      ///< what is fitted, e.g. "mu_r (all pairs)"
  std::string unit;           ///< "1", "J/m^3", "spheres"
  double lo = 0.0, hi = 1.0;  ///< plausible physical range
  double baseline = 0.0;      ///< the parameter value equivalent to the baseline model
  double probe = 0.0;         ///< the perturbation used for the local sensitivity
  bool discrete = false;      ///< levels instead of a continuous fit
  std::vector<double> levels;
  std::vector<std::string> level_names;
  /// The baseline model with this effect set to `value`.
  std::function<ParticleModel(const ParticleModel&, double)> apply;
  /// An effect the baseline holds at different values per partner material: every partner's
  /// value when the parameter is `value` (the other partners move with it; docs/calibrate.md).
  /// Empty: one value for every partner.
  std::function<std::map<std::string, double>(double)> partners;
  std::string format(double value) const;  ///< "0.083" / "rolling_model=cdt" / "12 spheres"
};

/// How `c` is named beside `other` (in a list of indistinguishable effects, a suggestion "a vs
/// b"): its effect id, with its parameter where both are forms of one effect
/// (size_distribution's mixture shares and height spread).
std::string name_beside(const EffectCandidate& c, const EffectCandidate& other);

/// Candidates for a baseline model. `only` (effect ids) restricts the list; unknown ids throw
/// InputError naming `where`. Effects that cannot be tried on this model (a height spread of
/// size_distribution on a type that is not a paper-rule cylinder; rolling_model without rolling
/// friction) are skipped and named in `skipped` with the reason.
std::vector<EffectCandidate> effect_candidates(const ParticleModel& base,
                                               const std::vector<std::string>& only,
                                               std::vector<std::string>* skipped,
                                               const std::string& where = "--effects");

}  // namespace clumpkit::calibrate
