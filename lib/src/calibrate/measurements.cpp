#include "clumpkit/calibrate/measurements.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/core/units.hpp"
#include "clumpkit/rigs/catalogue.hpp"

namespace clumpkit {

std::string Measurement::setting_text() const {
  return format_settings(setting);
}

std::string Measurement::key() const {
  return rig + "|" + sample + "|" + setting_text() + "|" + quantity;
}

namespace {

// Splits one CSV record (RFC 4180 quotes allowed; no embedded newlines).
std::vector<std::string> split_csv(const std::string& line, const std::string& where) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cur += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cur += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (quoted) throw InputError(where, "", "unterminated quote");
  out.push_back(cur);
  for (auto& s : out) {
    const auto b = s.find_first_not_of(" \t\r"), e = s.find_last_not_of(" \t\r");
    s = b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
  }
  return out;
}

double parse_number(const std::string& s, const std::string& where, const std::string& col) {
  if (s.empty()) throw InputError(where, col, "missing value");
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (!end || *end != 0) throw InputError(where, col, "'" + s + "' is not a number");
  if (!std::isfinite(v)) throw InputError(where, col, "'" + s + "' is not finite");
  return v;
}

}  // namespace

std::vector<Measurement> parse_measurements(const std::string& text, const std::string& name) {
  static const char* required[] = {"rig",   "sample", "setting", "quantity",
                                   "value", "std",    "n",       "unit"};
  std::istringstream in(text);
  std::string line;
  int lineno = 0;
  std::map<std::string, size_t> col;
  std::vector<Measurement> out;
  std::map<std::string, int> seen;
  while (std::getline(in, line)) {
    ++lineno;
    if (lineno == 1 && line.size() >= 3 && line.compare(0, 3, "\xEF\xBB\xBF") == 0)
      line.erase(0, 3);  // UTF-8 byte-order mark from spreadsheet exports
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::string where = name + ":" + std::to_string(lineno);
    const auto cells = split_csv(line, where);
    if (col.empty()) {
      for (size_t i = 0; i < cells.size(); ++i) {
        if (col.count(cells[i])) throw InputError(where, cells[i], "column given twice");
        col[cells[i]] = i;
      }
      // A European spreadsheet's export separates with semicolons (decimal commas inside).
      if (cells.size() == 1 && cells[0].find(';') != std::string::npos)
        throw InputError(where, "",
                         "the header is separated by ';', not ',' (export the sheet as "
                         "comma-separated values with decimal points)");
      for (const char* r : required)
        if (!col.count(r))
          throw InputError(where, r,
                           "missing column (header must hold rig,sample,setting,quantity,value,"
                           "std,n,unit)");
      continue;
    }
    auto cell = [&](const char* c) -> std::string {
      const size_t i = col.at(c);
      return i < cells.size() ? cells[i] : std::string();
    };
    Measurement m;
    m.line = lineno;
    m.rig = cell("rig");
    if (m.rig.empty()) throw InputError(where, "rig", "missing");
    const RigInfo& rig = find_rig(m.rig, where, "rig");
    m.sample = cell("sample");
    bool sample_ok = false;
    for (const auto& s : known_samples()) sample_ok |= s == m.sample;
    if (!sample_ok)
      throw InputError(where, "sample", "unknown sample '" + m.sample + "' (known: A, B, C, mix)");
    m.setting = parse_settings(rig, cell("setting"), where, "setting");
    m.quantity = cell("quantity");
    const QuantityInfo* q = rig.quantity(m.quantity);
    if (!q) {
      std::string known;
      for (const auto& k : rig.quantities) known += (known.empty() ? "" : ", ") + k.name;
      throw InputError(
          where, "quantity",
          "rig '" + m.rig + "' does not measure '" + m.quantity + "' (known: " + known + ")");
    }
    std::string unit = cell("unit");
    if (unit == "-" || unit == "") unit = q->dimension == Dimension::Dimensionless ? "1" : unit;
    if (unit.empty()) throw InputError(where, "unit", "missing (expected " + q->unit + ")");
    // A compatible unit is converted to the canonical one ("g" -> "kg"); another dimension is an
    // error.
    const double factor = unit_factor(unit, q->dimension, where, "unit") /
                          unit_factor(q->unit == "1" ? "" : q->unit, q->dimension);
    m.unit = q->unit;
    // Finite as written can overflow in the canonical unit (1e307 rad in degrees).
    const auto in_range = [&](double v, const char* field) {
      if (!std::isfinite(v))
        throw InputError(where, field,
                         "'" + cell(field) + " " + unit + "' is out of range in " + m.unit);
      return v;
    };
    m.value = in_range(parse_number(cell("value"), where, "value") * factor, "value");
    const std::string std_text = cell("std");
    if (std_text.empty())
      throw InputError(where, "std",
                       "missing: the standard deviation of the repeats is needed to "
                       "weigh this measurement");
    m.std = in_range(parse_number(std_text, where, "std") * factor, "std");
    if (m.std <= 0) throw InputError(where, "std", "must be positive (got " + std_text + ")");
    const double n = parse_number(cell("n"), where, "n");
    if (n < 1 || n != std::floor(n) || n > 1e6)
      throw InputError(where, "n",
                       "must be a whole number of repeats >= 1 (got " + cell("n") + ")");
    m.n = static_cast<int>(n);
    if (q->dimension != Dimension::Angle && m.value < 0)
      throw InputError(where, "value", "must not be negative");
    if (auto it = seen.find(m.key()); it != seen.end())
      throw InputError(where, "",
                       "duplicate of line " + std::to_string(it->second) + " (" + m.rig + ", " +
                           m.sample + ", '" + m.setting_text() + "', " + m.quantity + ")");
    seen[m.key()] = lineno;
    out.push_back(std::move(m));
  }
  if (col.empty()) throw InputError(name, "", "empty file: no header line");
  if (out.empty()) throw InputError(name, "", "no measurements (only a header)");
  return out;
}

std::vector<Measurement> load_measurements(const std::filesystem::path& path) {
  return parse_measurements(read_file(path), path.string());
}

std::vector<std::string> redundancy_warnings(const std::vector<Measurement>& ms,
                                             const std::string& name) {
  std::vector<std::string> out;
  for (size_t i = 0; i < ms.size(); ++i)
    for (size_t j = i + 1; j < ms.size(); ++j) {
      const Measurement &a = ms[i], &b = ms[j];
      if (a.rig != b.rig || a.sample != b.sample || a.setting != b.setting) continue;
      const std::vector<std::string> same = same_measurement_as(a.rig, a.quantity);
      if (std::find(same.begin(), same.end(), b.quantity) == same.end()) continue;
      // (fmt, not operator+: GCC 12 warns -Wrestrict on the concatenation, a false positive.)
      const std::string where =
          a.setting.empty() ? a.rig : fmt::format("{} {}", a.rig, a.setting_text());
      out.push_back(fmt::format(
          "{}:{} ({}) and line {} ({}), {}: one is computed from the other in every rig run, so "
          "chi-squared counts this measurement twice; give one of them",
          name, a.line, a.quantity, b.line, b.quantity, where));
    }
  return out;
}

std::string format_measurements(const std::vector<Measurement>& ms) {
  std::ostringstream out;
  out.precision(10);
  out << "rig,sample,setting,quantity,value,std,n,unit\n";
  for (const auto& m : ms)
    out << m.rig << "," << m.sample << "," << m.setting_text() << "," << m.quantity << ","
        << m.value << "," << m.std << "," << m.n << "," << m.unit << "\n";
  return out.str();
}

}  // namespace clumpkit
