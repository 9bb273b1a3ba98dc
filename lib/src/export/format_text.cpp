#include "format_text.hpp"

#include <fmt/format.h>

#include <cmath>

#include "clumpkit/core/error.hpp"

namespace clumpkit::export_detail {

std::string num(double v) {
  return fmt::format("{:.17g}", v);
}

namespace {

std::string vec3(const Eigen::Vector3d& v) {
  return num(v[0]) + " " + num(v[1]) + " " + num(v[2]);
}

// Some readers (LAMMPS reads molecule files in 256-byte lines) break on long lines, so long JSON
// provenance is wrapped.
void wrapped(std::string& out, std::string_view prefix, std::string_view label,
             const std::string& text) {
  constexpr size_t kWidth = 96;
  out += fmt::format("{}{}:\n", prefix, label);
  for (size_t i = 0; i < text.size(); i += kWidth)
    out += fmt::format("{}  {}\n", prefix, text.substr(i, kWidth));
}

}  // namespace

std::string provenance_block(const ClumpTemplate& c, std::string_view format,
                             std::string_view prefix) {
  const MassProperties& m = c.mass;
  const auto p = prefix;
  std::string o;
  o += fmt::format("{}clumpkit export ({}) of clump '{}' ({} spheres)\n", p, format,
                   c.name.empty() ? "clump" : c.name, c.spheres.size());
  o += fmt::format("{}units: SI (m, kg, kg/m^3, m^3, kg m^2)\n", p);
  o += fmt::format("{}frame: centroid-principal frame of the sphere union (the template frame)\n",
                   p);
  o += fmt::format("{}to source frame: p_source = R * p_template + t\n", p);
  for (int i = 0; i < 3; ++i)
    o += fmt::format("{}  R row {}: {}\n", p, i + 1, vec3(c.rotation.row(i).transpose()));
  o += fmt::format("{}  t [m]: {}\n", p, vec3(c.translation));
  o += fmt::format("{}mass properties of the sphere UNION (basis: {}), not the sum of spheres:\n",
                   p, c.mass_method.value("basis", "sphere_union"));
  o += fmt::format("{}  density [kg/m^3]: {}\n", p, num(m.density));
  o += fmt::format("{}  volume [m^3]: {}\n", p, num(m.volume));
  o += fmt::format("{}  mass [kg]: {}\n", p, num(m.mass));
  o += fmt::format("{}  center_of_mass [m]: {}\n", p, vec3(m.center_of_mass));
  o += fmt::format("{}  principal_moments [kg m^2]: {}\n", p, vec3(m.principal_moments));
  for (int i = 0; i < 3; ++i)
    o += fmt::format("{}  inertia_tensor row {} [kg m^2]: {}\n", p, i + 1,
                     vec3(m.inertia_tensor.row(i).transpose()));
  o += fmt::format("{}  95% half-widths: volume {} m^3, principal moments {} kg m^2\n", p,
                   num(c.mass_ci.volume), vec3(c.mass_ci.principal_moments));
  if (!c.source.empty()) wrapped(o, p, "source", c.source.dump());
  if (!c.method.empty()) wrapped(o, p, "method", c.method.dump());
  if (!c.mass_method.empty()) wrapped(o, p, "mass method", c.mass_method.dump());
  return o;
}

std::vector<double> volume_weighted_masses(const ClumpTemplate& c) {
  double sum = 0.0;
  for (const Sphere& s : c.spheres) sum += s.radius * s.radius * s.radius;
  std::vector<double> out;
  out.reserve(c.spheres.size());
  for (const Sphere& s : c.spheres)
    out.push_back(c.mass.mass * s.radius * s.radius * s.radius / sum);
  return out;
}

void require_principal_frame(const ClumpTemplate& c, std::string_view format) {
  const double size = bounds(c.spheres).diagonal().norm();
  // Sampling leaves the centre of mass within its confidence interval of the origin when the
  // template snapped it there (see make_clump_template); that is the same 1e-4 bound.
  if (c.mass.center_of_mass.norm() > 1e-4 * size)
    throw InputError("", "mass_properties.center_of_mass",
                     fmt::format("the {} export needs the template in its centroid frame, but the "
                                 "centre of mass is {} m from the origin",
                                 format, c.mass.center_of_mass.norm()));
  const Eigen::Matrix3d& I = c.mass.inertia_tensor;
  const double scale = I.diagonal().cwiseAbs().maxCoeff();
  const double off = std::max({std::abs(I(0, 1)), std::abs(I(0, 2)), std::abs(I(1, 2))});
  // Templates snap near-principal axes to the coordinate axes (mass_properties), leaving sampled
  // off-diagonal terms of order 1e-6 of the moments; 1e-3 still means "principal" to any code.
  if (!(off <= 1e-3 * scale))
    throw InputError("", "mass_properties.inertia_tensor",
                     fmt::format("the {} export needs the template in its principal frame, but the "
                                 "inertia tensor has off-diagonal {} kg m^2 (largest moment {})",
                                 format, off, scale));
}

Eigen::Matrix3d principal_inertia(const ClumpTemplate& c) {
  return c.mass.principal_moments.asDiagonal();
}

}  // namespace clumpkit::export_detail
