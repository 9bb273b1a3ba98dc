#include "suggestion.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "clumpkit/rigs/catalogue.hpp"

namespace clumpkit::calibrate {

void suggest_measurement(const ParticleModel& base, const std::vector<Measurement>& ms,
                         Simulator& sim, const DiagnoseOptions& o, double baseline_weight,
                         Diagnosis& d) {
  auto say = [&](const std::string& s) {
    if (o.progress) o.progress(s);
  };
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
        s.between =
            name_beside(a.candidate, b.candidate) + " vs " + name_beside(b.candidate, a.candidate);
        d.suggestions.push_back(s);
      }
    }
    std::sort(d.suggestions.begin(), d.suggestions.end(),
              [](const Suggestion& x, const Suggestion& y) { return x.separation > y.separation; });
    if (d.suggestions.empty())
      d.suggestion_note = trial.empty() ? "none: every experimental setting is measured already"
                                        : "none: no unmeasured setting could be simulated";
  }
}

}  // namespace clumpkit::calibrate
