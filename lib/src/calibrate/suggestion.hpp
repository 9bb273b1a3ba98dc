#pragma once
/// The diagnosis's last step (diagnosis.cpp): which unmeasured rig setting would best separate
/// the two leading explanations? Both are simulated, with every repeat, at up to
/// DiagnoseOptions::suggest_max experimental settings the measurements lack (the other cups, the
/// discharger's speeds), and each setting's observables are ranked by how many expected
/// measurement standard deviations apart the two predictions lie. Only asked where the answer is
/// needed: not for a consistent model or a decisive verdict, unless
/// DiagnoseOptions::suggest_always.
#include <vector>

#include "clumpkit/calibrate/diagnosis.hpp"

namespace clumpkit::calibrate {

/// Fills `d.suggestions` (best first), or `d.suggestion_note` with why none was simulated.
/// `d` is ranked (candidates best first, verdict, confidence); `baseline_weight` is the
/// baseline's posterior weight among the baseline and the candidates.
void suggest_measurement(const ParticleModel& base, const std::vector<Measurement>& ms,
                         Simulator& sim, const DiagnoseOptions& o, double baseline_weight,
                         Diagnosis& d);

}  // namespace clumpkit::calibrate
