#pragma once
/// Material library: bulk properties per material and contact properties per material pair
/// (paper Table 1). Read from a TOML file such as shapes/materials.toml.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace clumpkit {

struct Material {
  std::string name;
  double density = 0.0;         ///< kg/m^3
  double poisson_ratio = 0.0;   ///< 1, in (-1, 0.5)
  double youngs_modulus = 0.0;  ///< Pa
  double shear_modulus() const { return youngs_modulus / (2.0 * (1.0 + poisson_ratio)); }
};

/// Contact properties of a pair of materials.
struct Interaction {
  double restitution = 0.5;       ///< e in (0, 1]
  double static_friction = 0.5;   ///< μs >= 0
  double rolling_friction = 0.0;  ///< μr >= 0, dimensionless (EDEM convention, torque μr R |Fn|)
};

class MaterialLibrary {
 public:
  /// Loads `path`; throws InputError naming file, line and key on bad or missing values.
  static MaterialLibrary load(const std::filesystem::path& path);
  /// The same from a file's text; `where` names the file in errors.
  static MaterialLibrary parse(const std::string& text, const std::string& where);
  /// The paper's Table 1 (pill, abs_plastic, organic_glass, galvanized_steel), built in.
  static MaterialLibrary paper_table1();

  void add(const Material& m);
  void set_interaction(const std::string& a, const std::string& b, const Interaction& i);

  bool has(const std::string& name) const { return materials_.count(name) != 0; }
  /// Throws InputError("unknown material ...", listing the known ones).
  const Material& get(const std::string& name, const std::string& where = "",
                      const std::string& field = "") const;
  /// Throws InputError if the pair has no interaction entry.
  const Interaction& interaction(const std::string& a, const std::string& b,
                                 const std::string& where = "") const;
  bool has_interaction(const std::string& a, const std::string& b) const;
  std::vector<std::string> names() const;

 private:
  static std::pair<std::string, std::string> key(const std::string& a, const std::string& b);
  std::map<std::string, Material> materials_;
  std::map<std::pair<std::string, std::string>, Interaction> interactions_;
};

}  // namespace clumpkit
