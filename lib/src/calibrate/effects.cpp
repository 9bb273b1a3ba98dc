#include "clumpkit/calibrate/effects.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <set>

#include "clumpkit/core/error.hpp"
#include "clumpkit/fill/paper_rule.hpp"
#include "clumpkit/geometry/clump_template.hpp"

namespace clumpkit::calibrate {

std::string EffectCandidate::format(double v) const {
  if (discrete) {
    for (size_t i = 0; i < levels.size(); ++i)
      if (levels[i] == v) return level_names[i];
    return fmt::format("{}", v);
  }
  return unit == "1" ? fmt::format("{:.4g}", v) : fmt::format("{:.4g} {}", v, unit);
}

std::string name_beside(const EffectCandidate& c, const EffectCandidate& other) {
  return c.effect == other.effect ? c.effect + " (" + c.parameter + ")" : c.effect;
}

namespace {

// The variant's name tells the progress lines which run is which: "base [rolling_friction=0.16]".
std::string variant_label(const std::string& key, const std::string& value) {
  std::string k = key.rfind("effects.", 0) == 0 ? key.substr(8) : key;
  std::string v = value;
  size_t used = 0;
  try {
    const double x = std::stod(value, &used);
    v = fmt::format("{:.4g}", x) + value.substr(used);
  } catch (const std::exception&) {
    // not a number: a level name such as "cdt"
  }
  return k + "=" + v;
}

ParticleModel with(const ParticleModel& base, const std::string& key, const std::string& value) {
  ParticleModel m = base;
  set_model_effect(m, key, value, "diagnosis");
  m.name = base.name + " [" + variant_label(key, value) + "]";
  return m;
}

// The partner a per-partner effect's one parameter stands for: `ref`, else the first one held.
std::string reference_partner(const std::map<std::string, double>& v, const std::string& ref) {
  return v.count(ref) || v.empty() ? ref : v.begin()->first;
}

double first_value(const std::optional<std::map<std::string, double>>& v, const std::string& k,
                   double fallback) {
  return v && !v->empty() ? v->at(reference_partner(*v, k)) : fallback;
}

// A partner material's value when the reference partner's is x, for an effect the baseline holds
// per partner (Table 1's pill-wall values differ by wall): the piecewise-linear map through
// (lo, lo), (x0, b) and (hi, hi), x0 being the reference's baseline value and b the partner's.
// So the candidate at x0 is the baseline model itself (its run is the candidate's point there),
// the baseline's contrasts between materials are kept near it and fade towards the range's ends,
// and every partner's value rises with x. A partner the baseline holds at the reference's value
// gets x itself (bit for bit: a uniform baseline gives uniform variants), as every partner does
// at the range's ends (a fit pinned at a bound runs the same model as a uniform baseline's), and
// one held outside [lo, hi] keeps its value.
double partner_value(double b, double x0, double lo, double hi, double x) {
  if (b == x0 || ((x == lo || x == hi) && b >= lo && b <= hi)) return x;  // the ends: exact
  if (x == x0 || b < lo || b > hi) return b;
  if (x < x0) return x0 > lo ? lo + (x - lo) * ((b - lo) / (x0 - lo)) : b;
  return hi > x0 ? b + (x - x0) * ((hi - b) / (hi - x0)) : b;
}

// A probe inside the range, a fixed step from the baseline, towards the range's middle.
double probe_from(double base, double step, double lo, double hi) {
  const double up = base + step, down = base - step;
  if (up <= hi && (base <= 0.5 * (lo + hi) || down < lo)) return up;
  return std::max(lo, down);
}

}  // namespace

std::vector<EffectCandidate> effect_candidates(const ParticleModel& base,
                                               const std::vector<std::string>& only,
                                               std::vector<std::string>* skipped,
                                               const std::string& where) {
  for (const auto& e : only) check_effect_name(e, where, "");
  auto wanted = [&](const std::string& e) {
    return only.empty() || std::find(only.begin(), only.end(), e) != only.end();
  };
  auto skip = [&](const std::string& e, const std::string& why) {
    if (skipped && wanted(e)) skipped->push_back(e + ": " + why);
  };
  const ModelEffects& fx = base.effects;
  std::vector<EffectCandidate> out;

  // A continuous effect: one parameter set through a model-file key (`unit` appended to values).
  // `partners`: an effect held per partner material; the parameter is the value of partner `ref`
  // and the others move with it (partner_value) where the baseline holds them apart.
  auto continuous = [&](const std::string& effect, const std::string& parameter,
                        const std::string& unit, double lo, double hi, double baseline, double step,
                        const std::optional<std::map<std::string, double>>* partners = nullptr,
                        const std::string& ref = "", const std::string& moved = "") {
    if (!wanted(effect)) return;
    EffectCandidate c;
    c.effect = effect;
    c.parameter = parameter;
    c.unit = unit;
    c.lo = lo;
    c.hi = hi;
    c.baseline = baseline;
    c.probe = probe_from(baseline, step, lo, hi);
    const std::string key = "effects." + effect;
    const std::string suffix = unit == "1" ? "" : " " + unit;
    const bool held = partners && *partners && !(*partners)->empty();
    const bool apart = held && std::any_of((*partners)->begin(), (*partners)->end(),
                                           [&](const auto& kv) { return kv.second != baseline; });
    if (!apart) {
      c.apply = [key, suffix](const ParticleModel& m, double v) {
        return with(m, key, fmt::format("{:.17g}{}", v, suffix));
      };
    } else {
      c.parameter = fmt::format(fmt::runtime(moved), reference_partner(**partners, ref));
      c.partners = [values = **partners, baseline, lo, hi](double v) {
        std::map<std::string, double> at;
        for (const auto& [partner, b] : values) at[partner] = partner_value(b, baseline, lo, hi, v);
        return at;
      };
      c.apply = [key, at = c.partners](const ParticleModel& m, double v) {
        ParticleModel variant = m;
        for (const auto& [partner, x] : at(v))
          set_model_effect(variant, key + "." + partner, fmt::format("{:.17g}", x), "diagnosis");
        variant.name = m.name + " [" + variant_label(key, fmt::format("{:.17g}", v)) + "]";
        return variant;
      };
    }
    out.push_back(c);
  };
  continuous("rolling_friction", "mu_r, pill-pill and pill-wall", "1", 0.0, 0.5,
             first_value(fx.rolling_friction, "pill", 0.0), 0.08, &fx.rolling_friction, "pill",
             "mu_r, pill-pill (the pill-wall values move with it from the baseline's)");
  continuous("particle_friction", "mu_s, pill-pill", "1", 0.0, 1.2,
             fx.particle_friction.value_or(0.0), 0.25);
  continuous("wall_friction", "mu_s, pill-wall (all wall materials)", "1", 0.0, 1.2,
             first_value(fx.wall_friction, "galvanized_steel", 0.0), 0.25, &fx.wall_friction,
             "galvanized_steel",
             "mu_s, pill-{} (the other walls move with it from the baseline's)");
  continuous("restitution", "e, all pairs", "1", 0.05, 1.0,
             first_value(fx.restitution, "pill", 1.0), 0.3, &fx.restitution, "pill",
             "e, pill-pill (the pill-wall values move with it from the baseline's)");
  continuous("cohesion", "SJKR energy density, pill-pill", "J/m^3", 0.0, 5e4,
             fx.cohesion.value_or(0.0), 8e3);
  if (wanted("shape_resolution")) {
    // The sphere counts every type can take: a paper-rule type its rule's presets; a type given
    // as a clump template (from `clumpkit fill` of a mesh or cylinder) is filled again by the
    // optimiser, at a ladder of counts.
    static const std::set<int> kOptimiserCounts = {2, 4, 8, 16, 32};
    std::set<int> common;
    bool first = true;
    int current = fx.shape_resolution.value_or(0);
    for (const auto& t : base.types) {
      std::set<int> s = kOptimiserCounts;
      if (t.paper_spheres) {
        const auto counts = paper_preset_counts(regime(t.shape.diameter, t.shape.height));
        s = std::set<int>(counts.begin(), counts.end());
        if (current == 0) current = *t.paper_spheres;
      } else if (current == 0) {
        current = static_cast<int>(load_clump(t.clump_path).spheres.size());
      }
      if (first)
        common = s;
      else {
        std::set<int> x;
        std::set_intersection(common.begin(), common.end(), s.begin(), s.end(),
                              std::inserter(x, x.begin()));
        common = x;
      }
      first = false;
    }
    common.erase(current);
    std::string blocked;  // a template's mesh to fill again is gone: set_model_effect says so
    try {
      if (!common.empty())
        with(base, "effects.shape_resolution", fmt::format("{}", *common.begin()));
    } catch (const InputError& e) {
      blocked = e.message();
    }
    if (!blocked.empty()) {
      skip("shape_resolution", blocked);
    } else if (common.empty()) {
      skip("shape_resolution",
           "no other sphere count fits every type (paper-rule types: their "
           "rule's presets; clump templates: 2, 4, 8, 16, 32 by the optimiser)");
    } else {
      EffectCandidate c;
      c.effect = "shape_resolution";
      c.parameter = "spheres per clump (paper rule, or the optimiser for a clump template)";
      c.unit = "spheres";
      c.discrete = true;
      c.baseline = current;
      for (int n : common) {
        c.levels.push_back(n);
        c.level_names.push_back(fmt::format("{} spheres", n));
      }
      c.lo = *common.begin();
      c.hi = *common.rbegin();
      c.apply = [](const ParticleModel& m, double v) {
        return with(m, "effects.shape_resolution", fmt::format("{}", static_cast<int>(v)));
      };
      out.push_back(c);
    }
  }
  if (wanted("rolling_model")) {
    if (!fx.rolling_friction) {
      skip("rolling_model", "needs rolling_friction on in the baseline");
    } else {
      EffectCandidate c;
      c.effect = "rolling_model";
      c.parameter = "rolling resistance model";
      c.unit = "";
      c.discrete = true;
      const auto cur = fx.rolling_model.value_or(dem::RollingModel::kStandard);
      c.baseline = static_cast<double>(static_cast<int>(cur));
      for (auto m :
           {dem::RollingModel::kStandard, dem::RollingModel::kCdt, dem::RollingModel::kEpsd})
        if (m != cur) {
          c.levels.push_back(static_cast<int>(m));
          c.level_names.push_back(std::string("rolling_model=") + dem::to_string(m));
        }
      c.lo = 0;
      c.hi = 2;
      c.apply = [](const ParticleModel& m, double v) {
        return with(m, "effects.rolling_model",
                    dem::to_string(static_cast<dem::RollingModel>(static_cast<int>(v))));
      };
      out.push_back(c);
    }
  }
  if (wanted("size_distribution") && base.types.size() > 1) {
    // A mixture's fractions: the first type's mass fraction, the others sharing the rest in the
    // baseline's ratios (a model of several types holds the effect on: its baseline is the
    // model file's fraction). The range keeps every type in the population.
    const ModelType& t = base.types.front();
    EffectCandidate c;
    c.effect = "size_distribution";
    c.parameter = "mass fraction of type " + t.name + " (the other types keep their ratios)";
    c.unit = "1";
    c.lo = std::min(0.02, t.mass_fraction);
    c.hi = std::max(0.98, t.mass_fraction);
    c.baseline = t.mass_fraction;
    c.probe = probe_from(c.baseline, 0.2, c.lo, c.hi);
    c.apply = [key = "effects.size_distribution." + t.name](const ParticleModel& m, double v) {
      return with(m, key, fmt::format("{:.17g}", v));
    };
    out.push_back(c);
  }
  if (wanted("size_distribution")) {
    // The spread of pill heights within each type.
    try {
      with(base, "effects.size_distribution", "0.1");
      continuous("size_distribution", "height spread (mass-weighted relative std)", "1", 0.0, 0.2,
                 fx.size_distribution ? fx.height_spread : 0.0, 0.1);
    } catch (const InputError& e) {
      skip("size_distribution", e.message());
    }
  }
  return out;
}

}  // namespace clumpkit::calibrate
