#pragma once
/// Typed, unit-aware access to a human-edited TOML file. Every accessor names the file and the
/// dotted key in its error, so a user sees "shapes/pill_A.toml: shape.height: ...".
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "clumpkit/core/units.hpp"

namespace toml {
inline namespace v3 {
class table;
}
}  // namespace toml

namespace clumpkit {

class TomlDoc {
 public:
  /// Parses a file; throws InputError with file:line:column on a syntax error.
  static TomlDoc load(const std::filesystem::path& path);
  static TomlDoc parse(const std::string& text, const std::string& name);

  TomlDoc(TomlDoc&&) noexcept;
  TomlDoc& operator=(TomlDoc&&) noexcept;
  ~TomlDoc();

  const std::string& name() const { return name_; }
  bool has(const std::string& key) const;

  /// A quantity: a string "6.0 mm", or a bare number for Dimensionless. Must be finite.
  double quantity(const std::string& key, Dimension d) const;
  std::optional<double> quantity_opt(const std::string& key, Dimension d) const;
  /// A 3-vector with one unit: "0 0 -9.81 m/s^2".
  Eigen::Vector3d vector(const std::string& key, Dimension d) const;
  std::optional<Eigen::Vector3d> vector_opt(const std::string& key, Dimension d) const;
  double number(const std::string& key) const;  // bare dimensionless number
  std::optional<double> number_opt(const std::string& key) const;
  std::string string(const std::string& key) const;
  std::optional<std::string> string_opt(const std::string& key) const;
  long long integer(const std::string& key) const;
  std::optional<long long> integer_opt(const std::string& key) const;
  std::optional<bool> boolean_opt(const std::string& key) const;
  /// Keys directly under a table (empty if the table is absent).
  std::vector<std::string> keys(const std::string& table) const;
  /// Number of entries of an array of tables (0 if absent); elements are addressed "arr.N.key".
  size_t array_size(const std::string& key) const;
  /// Strings of an array of strings.
  std::vector<std::string> strings(const std::string& key) const;

  /// Throws unless a number lies in [lo, hi] (inclusive flags set by the caller's wording).
  void require_range(const std::string& key, double value, double lo, double hi,
                     bool lo_open = false, bool hi_open = false) const;
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  TomlDoc(std::unique_ptr<toml::table> t, std::string name);
  const void* find(const std::string& key) const;  // toml::node*
  std::unique_ptr<toml::table> table_;
  std::string name_;
};

}  // namespace clumpkit
