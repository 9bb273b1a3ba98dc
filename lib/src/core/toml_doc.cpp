#include "clumpkit/core/toml_doc.hpp"

#include <toml++/toml.h>
#include <cmath>
#include <sstream>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"

namespace clumpkit {

namespace {
std::string fmt_num(double v) {
  std::ostringstream ss;
  ss << v;
  return ss.str();
}
}  // namespace

TomlDoc::TomlDoc(std::unique_ptr<toml::table> t, std::string name)
    : table_(std::move(t)), name_(std::move(name)) {}
TomlDoc::TomlDoc(TomlDoc&&) noexcept = default;
TomlDoc& TomlDoc::operator=(TomlDoc&&) noexcept = default;
TomlDoc::~TomlDoc() = default;

TomlDoc TomlDoc::load(const std::filesystem::path& path) {
  return parse(read_file(path), path.string());
}

TomlDoc TomlDoc::parse(const std::string& text, const std::string& name) {
  try {
    auto t = std::make_unique<toml::table>(toml::parse(text, name));
    return TomlDoc(std::move(t), name);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw InputError(name + ":" + std::to_string(b.line) + ":" + std::to_string(b.column), "",
                     std::string(e.description()));
  }
}

const void* TomlDoc::find(const std::string& key) const {
  // Dotted path; numeric components index arrays ("factory.0.count").
  const toml::node* node = table_.get();
  std::stringstream ss(key);
  std::string part;
  while (node && std::getline(ss, part, '.')) {
    if (const auto* tbl = node->as_table()) {
      node = tbl->get(part);
    } else if (const auto* arr = node->as_array()) {
      char* end = nullptr;
      unsigned long idx = std::strtoul(part.c_str(), &end, 10);
      node = (end && *end == 0 && idx < arr->size()) ? arr->get(idx) : nullptr;
    } else {
      node = nullptr;
    }
  }
  return node;
}

bool TomlDoc::has(const std::string& key) const {
  return find(key) != nullptr;
}

void TomlDoc::fail(const std::string& key, const std::string& what) const {
  const auto* node = static_cast<const toml::node*>(find(key));
  std::string where = name_;
  if (node && node->source().begin.line > 0)
    where += ":" + std::to_string(node->source().begin.line);
  throw InputError(where, key, what);
}

std::optional<double> TomlDoc::quantity_opt(const std::string& key, Dimension d) const {
  const auto* node = static_cast<const toml::node*>(find(key));
  if (!node) return std::nullopt;
  std::string where = name_ + ":" + std::to_string(node->source().begin.line);
  if (auto s = node->value<std::string>()) return parse_quantity(*s, d, where, key);
  if (node->is_number()) {
    double v = *node->value<double>();
    if (!std::isfinite(v)) fail(key, "value is not finite");
    if (d != Dimension::Dimensionless)
      fail(key, "a " + std::string(dimension_name(d)) + " needs a unit, e.g. \"" + fmt_num(v) +
                    " " + si_unit(d) + "\"");
    return v;
  }
  fail(key, "expected a quantity such as \"1.0 " + std::string(si_unit(d)) + "\"");
}

double TomlDoc::quantity(const std::string& key, Dimension d) const {
  auto v = quantity_opt(key, d);
  if (!v) throw InputError(name_, key, "missing (a " + std::string(dimension_name(d)) + ")");
  return *v;
}

std::optional<Eigen::Vector3d> TomlDoc::vector_opt(const std::string& key, Dimension d) const {
  const auto* node = static_cast<const toml::node*>(find(key));
  if (!node) return std::nullopt;
  std::string where = name_ + ":" + std::to_string(node->source().begin.line);
  if (auto s = node->value<std::string>()) return parse_vector(*s, d, where, key);
  fail(key, "expected a vector such as \"0 0 1 " + std::string(si_unit(d)) + "\"");
}

Eigen::Vector3d TomlDoc::vector(const std::string& key, Dimension d) const {
  auto v = vector_opt(key, d);
  if (!v)
    throw InputError(name_, key, "missing (a vector of " + std::string(dimension_name(d)) + ")");
  return *v;
}

std::optional<double> TomlDoc::number_opt(const std::string& key) const {
  return quantity_opt(key, Dimension::Dimensionless);
}
double TomlDoc::number(const std::string& key) const {
  return quantity(key, Dimension::Dimensionless);
}

std::optional<std::string> TomlDoc::string_opt(const std::string& key) const {
  const auto* node = static_cast<const toml::node*>(find(key));
  if (!node) return std::nullopt;
  if (auto s = node->value<std::string>()) return *s;
  fail(key, "expected a string");
}
std::string TomlDoc::string(const std::string& key) const {
  auto v = string_opt(key);
  if (!v) throw InputError(name_, key, "missing (a string)");
  return *v;
}

std::optional<long long> TomlDoc::integer_opt(const std::string& key) const {
  const auto* node = static_cast<const toml::node*>(find(key));
  if (!node) return std::nullopt;
  if (node->is_integer()) return *node->value<long long>();
  fail(key, "expected a whole number");
}
long long TomlDoc::integer(const std::string& key) const {
  auto v = integer_opt(key);
  if (!v) throw InputError(name_, key, "missing (a whole number)");
  return *v;
}

std::optional<bool> TomlDoc::boolean_opt(const std::string& key) const {
  const auto* node = static_cast<const toml::node*>(find(key));
  if (!node) return std::nullopt;
  if (node->is_boolean()) return *node->value<bool>();
  fail(key, "expected true or false");
}

std::vector<std::string> TomlDoc::keys(const std::string& table) const {
  std::vector<std::string> out;
  const auto* node = table.empty() ? static_cast<const toml::node*>(table_.get())
                                   : static_cast<const toml::node*>(find(table));
  if (!node) return out;
  const auto* tbl = node->as_table();
  if (!tbl) fail(table, "expected a table");
  for (const auto& [k, v] : *tbl) out.emplace_back(k.str());
  return out;
}

size_t TomlDoc::array_size(const std::string& key) const {
  const auto* node = static_cast<const toml::node*>(find(key));
  if (!node) return 0;
  const auto* arr = node->as_array();
  if (!arr) fail(key, "expected an array");
  return arr->size();
}

std::vector<std::string> TomlDoc::strings(const std::string& key) const {
  std::vector<std::string> out;
  const size_t n = array_size(key);
  for (size_t i = 0; i < n; ++i) out.push_back(string(key + "." + std::to_string(i)));
  return out;
}

void TomlDoc::require_range(const std::string& key, double value, double lo, double hi,
                            bool lo_open, bool hi_open) const {
  const bool ok = (lo_open ? value > lo : value >= lo) && (hi_open ? value < hi : value <= hi);
  if (!ok)
    fail(key, "value " + fmt_num(value) + " is outside " + (lo_open ? "(" : "[") + fmt_num(lo) +
                  ", " + fmt_num(hi) + (hi_open ? ")" : "]"));
}

}  // namespace clumpkit
