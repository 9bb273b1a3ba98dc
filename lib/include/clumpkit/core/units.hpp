#pragma once
/// Quantities with units in human-edited files: "6.0 mm", "1380 kg/m^3", "200 mm/min".
/// Everything inside clumpkit is SI; units exist only at the file boundary.
#include <Eigen/Core>
#include <string>
#include <string_view>

namespace clumpkit {

enum class Dimension {
  Dimensionless,
  Length,           // m
  Mass,             // kg
  Time,             // s
  Density,          // kg/m^3
  Pressure,         // Pa
  Velocity,         // m/s
  Angle,            // rad
  AngularVelocity,  // rad/s
  Volume,           // m^3
  Energy,           // J
  SurfaceEnergy,    // J/m^2
  Acceleration,     // m/s^2
  MassFlow,         // kg/s
};

const char* si_unit(Dimension d);
const char* dimension_name(Dimension d);

/// Parses "value unit" into SI. Throws InputError (field named) on a malformed number, a unit of
/// another dimension, or a non-finite value. A bare number is accepted only for Dimensionless.
double parse_quantity(std::string_view text, Dimension d, const std::string& where = "",
                      const std::string& field = "");

/// Parses a 3-vector "0 0 -9.81 m/s^2" (three numbers, one unit for all) into SI.
Eigen::Vector3d parse_vector(std::string_view text, Dimension d, const std::string& where = "",
                             const std::string& field = "");

/// Factor that converts one unit to SI; throws InputError if unknown or of another dimension.
double unit_factor(std::string_view unit, Dimension d, const std::string& where = "",
                   const std::string& field = "");

}  // namespace clumpkit
