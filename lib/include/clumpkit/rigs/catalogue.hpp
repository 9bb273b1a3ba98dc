#pragma once
/// What each validation rig measures and which settings it accepts (SPEC §7, §8). Shared by the
/// rigs themselves, the measurement reader and the calibration loop, so that a name unknown here
/// is refused everywhere with the same message.
#include <map>
#include <string>
#include <vector>

#include "clumpkit/core/units.hpp"

namespace clumpkit {

struct QuantityInfo {
  std::string name;  ///< e.g. "angle"
  Dimension dimension;
  std::string unit;         ///< canonical unit in files and reports ("deg", "kg/m^3", "1")
  double to_si = 1.0;       ///< canonical unit -> SI factor (deg -> rad is pi/180)
  std::string description;  ///< one line, for --help and reports
};

struct SettingInfo {
  std::string key;                   ///< e.g. "rpm"
  std::vector<std::string> choices;  ///< allowed values; empty: a number with `unit`
  std::string unit;                  ///< unit of a numeric setting ("rpm"); empty for choices
  std::string default_value;
  std::string description;
  /// A setting of the experiment itself (a wall material, a wheel speed), as opposed to one of
  /// the simulation (scale, stiffness, implicit damping): only these are suggested as a next
  /// measurement.
  bool experimental = true;
};

struct RigInfo {
  std::string name;  ///< "bulk_density", "angle_of_repose", "discharge"
  std::string description;
  std::vector<QuantityInfo> quantities;
  std::vector<SettingInfo> settings;
  const QuantityInfo* quantity(const std::string& name) const;
  const SettingInfo* setting(const std::string& key) const;
};

/// The rigs, in pipeline order.
const std::vector<RigInfo>& rig_catalogue();
/// Throws InputError(where, field, "unknown rig ... (known: ...)").
const RigInfo& find_rig(const std::string& name, const std::string& where = "",
                        const std::string& field = "rig");

/// The other quantities of the same rig run that `quantity` is computed from or that are
/// computed from it, so that measuring both counts one measurement twice in a chi-squared sum:
/// discharge's mass_flow is pocket_mass x pockets x rpm / 60; angle_of_repose's angle is the mean
/// of angle_left and angle_right. Empty for an independent quantity.
std::vector<std::string> same_measurement_as(const std::string& rig, const std::string& quantity);

/// Samples a measurement may refer to: a pill type or the production mixture.
const std::vector<std::string>& known_samples();

/// A parsed setting string "rpm=15;plate=galvanized_steel" (empty string: defaults only), checked
/// against the rig and normalised (sorted keys, canonical number formatting) so that equal settings
/// compare equal. Throws InputError on an unknown key, a bad value or a repeated key.
std::map<std::string, std::string> parse_settings(const RigInfo& rig, const std::string& text,
                                                  const std::string& where,
                                                  const std::string& field = "setting");
std::string format_settings(const std::map<std::string, std::string>& settings);

}  // namespace clumpkit
