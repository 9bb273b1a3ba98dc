#include "clumpkit/core/units.hpp"

#include <charconv>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "clumpkit/core/error.hpp"

namespace clumpkit {

namespace {
struct Unit {
  const char* name;
  Dimension dim;
  double factor;
};

const std::vector<Unit>& units() {
  // Besides the ASCII spellings, those a lab spreadsheet writes: superscripts (kg/m³), the
  // degree sign, the micro sign and Greek mu, litres for densities, mass flows per minute and
  // hour.
  static const std::vector<Unit> table = {
      {"", Dimension::Dimensionless, 1.0},
      {"1", Dimension::Dimensionless, 1.0},
      {"%", Dimension::Dimensionless, 0.01},
      {"m", Dimension::Length, 1.0},
      {"cm", Dimension::Length, 1e-2},
      {"mm", Dimension::Length, 1e-3},
      {"um", Dimension::Length, 1e-6},
      {"µm", Dimension::Length, 1e-6},
      {"μm", Dimension::Length, 1e-6},
      {"kg", Dimension::Mass, 1.0},
      {"g", Dimension::Mass, 1e-3},
      {"mg", Dimension::Mass, 1e-6},
      {"s", Dimension::Time, 1.0},
      {"ms", Dimension::Time, 1e-3},
      {"us", Dimension::Time, 1e-6},
      {"µs", Dimension::Time, 1e-6},
      {"μs", Dimension::Time, 1e-6},
      {"h", Dimension::Time, 3600.0},
      {"min", Dimension::Time, 60.0},
      {"kg/m^3", Dimension::Density, 1.0},
      {"kg/m3", Dimension::Density, 1.0},
      {"g/cm^3", Dimension::Density, 1000.0},
      {"g/cm3", Dimension::Density, 1000.0},
      {"kg/m³", Dimension::Density, 1.0},
      {"g/cm³", Dimension::Density, 1000.0},
      {"g/L", Dimension::Density, 1.0},
      {"kg/L", Dimension::Density, 1000.0},
      {"g/mL", Dimension::Density, 1000.0},
      {"g/ml", Dimension::Density, 1000.0},
      {"Pa", Dimension::Pressure, 1.0},
      {"kPa", Dimension::Pressure, 1e3},
      {"MPa", Dimension::Pressure, 1e6},
      {"GPa", Dimension::Pressure, 1e9},
      {"J/m^3", Dimension::Pressure, 1.0},  // energy density (cohesion) has pressure's dimension
      {"kJ/m^3", Dimension::Pressure, 1e3},
      {"J/m³", Dimension::Pressure, 1.0},
      {"kJ/m³", Dimension::Pressure, 1e3},
      {"m/s", Dimension::Velocity, 1.0},
      {"mm/s", Dimension::Velocity, 1e-3},
      {"mm/min", Dimension::Velocity, 1e-3 / 60.0},
      {"rad", Dimension::Angle, 1.0},
      {"deg", Dimension::Angle, std::numbers::pi / 180.0},
      {"°", Dimension::Angle, std::numbers::pi / 180.0},
      {"degree", Dimension::Angle, std::numbers::pi / 180.0},
      {"degrees", Dimension::Angle, std::numbers::pi / 180.0},
      {"rad/s", Dimension::AngularVelocity, 1.0},
      {"rpm", Dimension::AngularVelocity, 2.0 * std::numbers::pi / 60.0},
      {"deg/s", Dimension::AngularVelocity, std::numbers::pi / 180.0},
      {"m^3", Dimension::Volume, 1.0},
      {"L", Dimension::Volume, 1e-3},
      {"mL", Dimension::Volume, 1e-6},
      {"mm^3", Dimension::Volume, 1e-9},
      {"m³", Dimension::Volume, 1.0},
      {"mm³", Dimension::Volume, 1e-9},
      {"ml", Dimension::Volume, 1e-6},
      {"J", Dimension::Energy, 1.0},
      {"J/m^2", Dimension::SurfaceEnergy, 1.0},
      {"mJ/m^2", Dimension::SurfaceEnergy, 1e-3},
      {"J/m²", Dimension::SurfaceEnergy, 1.0},
      {"mJ/m²", Dimension::SurfaceEnergy, 1e-3},
      {"m/s^2", Dimension::Acceleration, 1.0},
      {"m/s²", Dimension::Acceleration, 1.0},
      {"kg/s", Dimension::MassFlow, 1.0},
      {"g/s", Dimension::MassFlow, 1e-3},
      {"kg/min", Dimension::MassFlow, 1.0 / 60.0},
      {"kg/h", Dimension::MassFlow, 1.0 / 3600.0},
      {"g/min", Dimension::MassFlow, 1e-3 / 60.0},
      {"t/h", Dimension::MassFlow, 1e3 / 3600.0},
  };
  return table;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}
}  // namespace

const char* si_unit(Dimension d) {
  switch (d) {
    case Dimension::Dimensionless:
      return "1";
    case Dimension::Length:
      return "m";
    case Dimension::Mass:
      return "kg";
    case Dimension::Time:
      return "s";
    case Dimension::Density:
      return "kg/m^3";
    case Dimension::Pressure:
      return "Pa";
    case Dimension::Velocity:
      return "m/s";
    case Dimension::Angle:
      return "rad";
    case Dimension::AngularVelocity:
      return "rad/s";
    case Dimension::Volume:
      return "m^3";
    case Dimension::Energy:
      return "J";
    case Dimension::SurfaceEnergy:
      return "J/m^2";
    case Dimension::Acceleration:
      return "m/s^2";
    case Dimension::MassFlow:
      return "kg/s";
  }
  return "?";
}

const char* dimension_name(Dimension d) {
  switch (d) {
    case Dimension::Dimensionless:
      return "dimensionless";
    case Dimension::Length:
      return "length";
    case Dimension::Mass:
      return "mass";
    case Dimension::Time:
      return "time";
    case Dimension::Density:
      return "density";
    case Dimension::Pressure:
      return "pressure";
    case Dimension::Velocity:
      return "velocity";
    case Dimension::Angle:
      return "angle";
    case Dimension::AngularVelocity:
      return "angular velocity";
    case Dimension::Volume:
      return "volume";
    case Dimension::Energy:
      return "energy";
    case Dimension::SurfaceEnergy:
      return "surface energy";
    case Dimension::Acceleration:
      return "acceleration";
    case Dimension::MassFlow:
      return "mass flow";
  }
  return "?";
}

double unit_factor(std::string_view unit, Dimension d, const std::string& where,
                   const std::string& field) {
  unit = trim(unit);
  bool known = false;
  for (const Unit& u : units()) {
    if (unit != u.name) continue;
    known = true;
    if (u.dim == d) return u.factor;
  }
  std::string expected = std::string("expected a ") + dimension_name(d) + " in " + si_unit(d);
  if (known)
    throw InputError(where, field,
                     "unit '" + std::string(unit) + "' is not a unit of " + dimension_name(d) +
                         " (" + expected + " or a compatible unit)");
  throw InputError(where, field, "unknown unit '" + std::string(unit) + "' (" + expected + ")");
}

double parse_quantity(std::string_view text, Dimension d, const std::string& where,
                      const std::string& field) {
  std::string_view s = trim(text);
  if (s.empty()) throw InputError(where, field, "empty value");
  double value = 0.0;
  const char* begin = s.data();
  const char* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr == begin)
    throw InputError(where, field, "'" + std::string(s) + "' is not a number with a unit");
  if (!std::isfinite(value))
    throw InputError(where, field, "value '" + std::string(s) + "' is not finite");
  std::string_view unit = trim(std::string_view(ptr, static_cast<size_t>(end - ptr)));
  if (unit.empty() && d != Dimension::Dimensionless)
    throw InputError(where, field,
                     "'" + std::string(s) + "' has no unit (expected a " + dimension_name(d) +
                         ", e.g. '" + std::string(s) + " " + si_unit(d) + "')");
  const double si = value * unit_factor(unit, d, where, field);
  if (!std::isfinite(si))  // "1e308 g/cm^3": finite as written, not in SI
    throw InputError(where, field, "value '" + std::string(s) + "' is out of range");
  return si;
}

Eigen::Vector3d parse_vector(std::string_view text, Dimension d, const std::string& where,
                             const std::string& field) {
  std::string_view s = trim(text);
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == ','))
      s.remove_prefix(1);
    double x = 0.0;
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), x);
    if (ec != std::errc() || ptr == s.data())
      throw InputError(where, field,
                       "'" + std::string(text) + "' is not three numbers and a unit (e.g. \"0 0 " +
                           "-9.81 m/s^2\")");
    if (!std::isfinite(x))
      throw InputError(where, field, "'" + std::string(text) + "' is not finite");
    v[k] = x;
    s.remove_prefix(static_cast<size_t>(ptr - s.data()));
  }
  s = trim(s);
  if (s.empty() && d != Dimension::Dimensionless)
    throw InputError(where, field,
                     "'" + std::string(text) + "' has no unit (expected a " + dimension_name(d) +
                         " in " + si_unit(d) + ")");
  return v * unit_factor(s, d, where, field);
}

}  // namespace clumpkit
