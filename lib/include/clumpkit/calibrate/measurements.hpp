#pragma once
/// Lab measurements (SPEC §8): CSV with the header `rig,sample,setting,quantity,value,std,n,unit`
/// (any column order, extra columns allowed, `#` comment lines and blank lines skipped).
/// Every line is validated; errors name the file, the line and the column.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace clumpkit {

struct Measurement {
  std::string rig;                             ///< a rig of rig_catalogue()
  std::string sample;                          ///< "A", "B", "C" or "mix"
  std::map<std::string, std::string> setting;  ///< normalised key=value pairs
  std::string quantity;                        ///< a quantity of the rig
  double value = 0.0;  ///< in the quantity's canonical unit (deg, kg/m^3, kg, 1, kg/s)
  double std = 0.0;    ///< standard deviation of the repeats, same unit, > 0
  int n = 1;           ///< number of repeats, >= 1
  std::string unit;    ///< canonical unit (the file's unit converted if compatible)
  int line = 0;        ///< line in the file, for messages
  /// Key identifying the observable: rig|sample|setting|quantity.
  std::string key() const;
  std::string setting_text() const;
};

/// Reads and validates a measurement file. Throws InputError "file:line: column: ..." on: a
/// missing column, an unknown rig, sample, quantity or setting, a unit that is not the quantity's
/// (nor convertible to it), a non-numeric or non-finite value, a missing, zero or negative std,
/// n < 1 or not an integer, a duplicate observable, or a file with no measurements.
std::vector<Measurement> load_measurements(const std::filesystem::path& path);
std::vector<Measurement> parse_measurements(const std::string& text, const std::string& name);

/// One warning per pair of observables of the same rig, sample and setting that are one
/// measurement (same_measurement_as: e.g. a discharge's mass flow and pocket mass), naming both
/// lines of `name`: chi-squared would count that measurement twice. Empty when there are none.
std::vector<std::string> redundancy_warnings(const std::vector<Measurement>& m,
                                             const std::string& name);

/// Writes measurements back as CSV (canonical units), e.g. for `clumpkit synth`.
std::string format_measurements(const std::vector<Measurement>& m);

}  // namespace clumpkit
