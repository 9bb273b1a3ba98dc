#include "clumpkit/rigs/catalogue.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "clumpkit/core/error.hpp"

namespace clumpkit {

const QuantityInfo* RigInfo::quantity(const std::string& n) const {
  for (const auto& q : quantities)
    if (q.name == n) return &q;
  return nullptr;
}

const SettingInfo* RigInfo::setting(const std::string& k) const {
  for (const auto& s : settings)
    if (s.key == k) return &s;
  return nullptr;
}

const std::vector<RigInfo>& rig_catalogue() {
  static const std::vector<RigInfo> rigs = [] {
    const double deg = std::numbers::pi / 180.0;
    const SettingInfo scale{"scale",
                            {"tiny", "mini", "small", "paper"},
                            "",
                            "mini",
                            "rig size: tiny (smoke tests, ~100-200 pills), mini (quick), small, "
                            "paper (the paper's sizes)",
                            false};
    const std::vector<std::string> walls = {"abs_plastic", "organic_glass", "galvanized_steel"};
    // A speed-up, not physics: every Young's modulus times this factor (the scale sets it).
    const SettingInfo stiffness{
        "stiffness", {}, "1", "1", "factor on every Young's modulus (scale default; 1 = Table 1)",
        false};
    // The time step, as a fraction of the smallest sphere's Rayleigh time (the scale sets it).
    const SettingInfo step{"rayleigh_fraction",
                           {},
                           "1",
                           "by scale",
                           "time step / the smallest sphere's Rayleigh time (scale default: 0.3 at "
                           "tiny and mini, 0.25 at small, 0.2 at paper; at most 0.4; an impact "
                           "needs 10 steps, which may cut it)",
                           false};
    // The engine's implicit-damping gate (WorldSettings::implicit_damping); 0 = off, the time
    // step then cut to the stiffest contact mode's damping rate as before session 10.
    const SettingInfo damping{"implicit_damping",
                              {"on", "off"},
                              "",
                              "on",
                              "jammed pills damped implicitly (off: explicit, a smaller step)",
                              false};
    std::vector<RigInfo> r;
    r.push_back(
        {"bulk_density",
         "0.26 L organic-glass cylinder, pour to overflow, strike off, weigh",
         {{"bulk_density", Dimension::Density, "kg/m^3", 1.0, "mass in the cylinder / 0.26 L"}},
         {scale,
          {"wall", walls, "", "organic_glass", "material of the measuring cylinder"},
          {"pour_region",
           {"whole", "centre"},
           "",
           "by scale",
           "pills wholly inside the pour region (tiny to small), or only their centres (paper: "
           "a faster pour)",
           false},
          stiffness,
          step,
          damping}});
    r.push_back({"angle_of_repose",
                 "lifting cylinder (200 mm/min) on a plate; heap angle from side silhouettes",
                 {{"angle", Dimension::Angle, "deg", deg, "mean of both flanks"},
                  {"angle_left", Dimension::Angle, "deg", deg, "left flank"},
                  {"angle_right", Dimension::Angle, "deg", deg, "right flank"}},
                 {scale,
                  {"plate", walls, "", "galvanized_steel", "material of the base plate"},
                  {"lift_speed", {}, "mm/min", "200", "lifting speed of the cylinder"},
                  {"mass",
                   {},
                   "kg",
                   "0.5",
                   "pill mass poured (scale default); what the cylinder cannot hold is poured "
                   "from above its top and runs over onto the plate"},
                  stiffness,
                  step,
                  damping}});
    r.push_back({"discharge",
                 "hopper and 8-pocket wheel at a given speed",
                 {{"pocket_mass", Dimension::Mass, "kg", 1.0, "mean mass per pocket"},
                  {"pocket_mass_cv", Dimension::Dimensionless, "1", 1.0,
                   "coefficient of variation of the pocket mass"},
                  {"mass_flow", Dimension::MassFlow, "kg/s", 1.0, "discharged mass per second"}},
                 {scale,
                  {"rpm", {}, "rpm", "15", "wheel speed"},
                  {"slice",
                   {},
                   "mm",
                   "20",
                   "length of the wheel slice along its axis (scale default: 24 mm at tiny "
                   "and mini, 20 mm at small and paper; the paper's pocket is 100 mm, and at "
                   "paper scale the bed is 10 kg per 100 mm of slice)"},
                  {"pockets", {}, "1", "8", "pockets measured after the first (scale default)"},
                  stiffness,
                  step,
                  damping}});
    return r;
  }();
  return rigs;
}

const RigInfo& find_rig(const std::string& name, const std::string& where,
                        const std::string& field) {
  std::string known;
  for (const auto& r : rig_catalogue()) {
    if (r.name == name) return r;
    known += (known.empty() ? "" : ", ") + r.name;
  }
  throw InputError(where, field, "unknown rig '" + name + "' (known: " + known + ")");
}

std::vector<std::string> same_measurement_as(const std::string& rig, const std::string& quantity) {
  if (rig == "discharge") {
    if (quantity == "mass_flow") return {"pocket_mass"};
    if (quantity == "pocket_mass") return {"mass_flow"};
  }
  if (rig == "angle_of_repose") {
    if (quantity == "angle") return {"angle_left", "angle_right"};
    if (quantity == "angle_left" || quantity == "angle_right") return {"angle"};
  }
  return {};
}

const std::vector<std::string>& known_samples() {
  static const std::vector<std::string> s = {"A", "B", "C", "mix"};
  return s;
}

std::map<std::string, std::string> parse_settings(const RigInfo& rig, const std::string& text,
                                                  const std::string& where,
                                                  const std::string& field) {
  std::map<std::string, std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ';')) {
    auto trim = [](std::string s) {
      const auto b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
      return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
    };
    item = trim(item);
    if (item.empty()) continue;
    const auto eq = item.find('=');
    if (eq == std::string::npos) throw InputError(where, field, "'" + item + "' is not key=value");
    const std::string key = trim(item.substr(0, eq)), value = trim(item.substr(eq + 1));
    const SettingInfo* s = rig.setting(key);
    if (!s) {
      std::string known;
      for (const auto& k : rig.settings) known += (known.empty() ? "" : ", ") + k.key;
      throw InputError(
          where, field,
          "rig '" + rig.name + "' has no setting '" + key + "' (known: " + known + ")");
    }
    if (out.count(key)) throw InputError(where, field, "setting '" + key + "' given twice");
    if (!s->choices.empty()) {
      bool ok = false;
      std::string known;
      for (const auto& c : s->choices) {
        ok |= c == value;
        known += (known.empty() ? "" : ", ") + c;
      }
      if (!ok)
        throw InputError(where, field,
                         "setting " + key + "='" + value + "' is not one of: " + known);
      out[key] = value;
    } else {
      char* end = nullptr;
      const double v = std::strtod(value.c_str(), &end);
      if (value.empty() || !end || *end != 0 || !std::isfinite(v) || v <= 0)
        throw InputError(
            where, field,
            "setting " + key + "='" + value + "' must be a positive number in " + s->unit);
      std::ostringstream num;
      num << v;
      out[key] = num.str();
    }
  }
  return out;
}

std::string format_settings(const std::map<std::string, std::string>& settings) {
  std::string s;
  for (const auto& [k, v] : settings) s += (s.empty() ? "" : ";") + k + "=" + v;
  return s;
}

}  // namespace clumpkit
