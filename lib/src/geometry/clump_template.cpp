#include "clumpkit/geometry/clump_template.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/geometry/sphere_union.hpp"

namespace clumpkit {

using nlohmann::json;

Spheres ClumpTemplate::spheres_in_source_frame() const {
  Spheres out = spheres;
  for (Sphere& s : out) s.center = rotation * s.center + translation;
  return out;
}

ClumpTemplate make_clump_template(const Spheres& src, double density,
                                  const RaySamplingOptions& sampling) {
  validate_spheres(src, "clump");
  ClumpTemplate c;
  SphereUnion u(src);
  auto samples = integrate_solid(u, sampling);
  MassPropertiesCI ci;
  MassProperties mp = mass_properties(samples, density, &ci);
  // The centre of mass snaps to the source origin where sampling cannot tell them apart: a
  // symmetric fill then keeps its exact, symmetric sphere positions.
  const double size = u.bounds().diagonal().norm();
  Eigen::Vector3d com = mp.center_of_mass;
  for (int k = 0; k < 3; ++k)
    if (std::abs(com[k]) <= 2.0 * ci.center_of_mass[k] + 1e-12 * size &&
        std::abs(com[k]) < 1e-4 * size)
      com[k] = 0.0;
  c.rotation = mp.principal_axes;
  c.translation = com;
  c.spheres = src;
  for (Sphere& s : c.spheres) s.center = c.rotation.transpose() * (s.center - com);
  c.mass = mp;
  c.mass.center_of_mass = c.rotation.transpose() * (mp.center_of_mass - com);
  c.mass.inertia_tensor = c.rotation.transpose() * mp.inertia_tensor * c.rotation;
  c.mass.principal_axes.setIdentity();
  c.mass_ci = ci;
  c.mass_method = {{"basis", "sphere_union"},
                   {"integration", "ray_sampling"},
                   {"rays", sampling.rays},
                   {"replicates", sampling.replicates},
                   {"seed", sampling.seed}};
  return c;
}

namespace {
json vec(const Eigen::Vector3d& v) {
  return json::array({v[0], v[1], v[2]});
}
json mat(const Eigen::Matrix3d& m) {
  json a = json::array();
  for (int i = 0; i < 3; ++i) a.push_back(json::array({m(i, 0), m(i, 1), m(i, 2)}));
  return a;
}

double num(const json& j, const std::string& where, const std::string& field) {
  if (!j.is_number()) throw InputError(where, field, "expected a number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) throw InputError(where, field, "value is not finite");
  return v;
}
const json& member(const json& j, const char* key, const std::string& where,
                   const std::string& parent) {
  const std::string field = parent.empty() ? key : parent + "." + key;
  if (!j.is_object()) throw InputError(where, parent, "expected an object");
  auto it = j.find(key);
  if (it == j.end()) throw InputError(where, field, "missing");
  return *it;
}
Eigen::Vector3d read_vec(const json& j, const std::string& where, const std::string& field) {
  if (!j.is_array() || j.size() != 3) throw InputError(where, field, "expected [x, y, z]");
  return {num(j[0], where, field + "[0]"), num(j[1], where, field + "[1]"),
          num(j[2], where, field + "[2]")};
}
Eigen::Matrix3d read_mat(const json& j, const std::string& where, const std::string& field) {
  if (!j.is_array() || j.size() != 3) throw InputError(where, field, "expected a 3x3 array");
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    m.row(i) = read_vec(j[i], where, field + "[" + std::to_string(i) + "]");
  return m;
}
}  // namespace

PrincipalFrame principal_frame(const MassProperties& mp) {
  Eigen::Matrix3d inertia = mp.inertia_tensor;
  if (inertia.isZero(0.0)) inertia = mp.principal_moments.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (inertia + inertia.transpose()));
  PrincipalFrame f{eig.eigenvalues(), eig.eigenvectors()};
  const double off = (inertia - Eigen::Matrix3d(inertia.diagonal().asDiagonal())).norm();
  if (off <= 1e-12 * inertia.norm()) {
    f.moments = inertia.diagonal();
    f.axes.setIdentity();
  } else if (f.axes.determinant() < 0) {
    f.axes.col(2) *= -1.0;
  }
  return f;
}

ClumpTemplate in_principal_frame(const ClumpTemplate& c) {
  const PrincipalFrame f = principal_frame(c.mass);
  const Eigen::Vector3d com = c.mass.center_of_mass;
  ClumpTemplate out = c;
  for (Sphere& s : out.spheres) s.center = f.axes.transpose() * (s.center - com);
  // p_source = R p + t with p = A p' + com.
  out.translation = c.rotation * com + c.translation;
  out.rotation = c.rotation * f.axes;
  out.mass.center_of_mass.setZero();
  out.mass.inertia_tensor = f.moments.asDiagonal();
  out.mass.principal_moments = f.moments;
  out.mass.principal_axes.setIdentity();
  return out;
}

json to_json(const ClumpTemplate& c) {
  json spheres = json::array();
  for (const Sphere& s : c.spheres)
    spheres.push_back(json::array({s.center[0], s.center[1], s.center[2], s.radius}));
  const MassProperties& m = c.mass;
  json j = {
      {"format", kClumpFormat},
      {"name", c.name},
      {"units", "SI: m, kg, kg m^2"},
      {"spheres", spheres},
      {"mass_properties",
       {{"basis", c.mass_method.value("basis", "sphere_union")},
        {"density", m.density},
        {"volume", m.volume},
        {"mass", m.mass},
        {"center_of_mass", vec(m.center_of_mass)},
        {"inertia_tensor", mat(m.inertia_tensor)},
        {"principal_moments", vec(m.principal_moments)},
        {"ci95",
         {{"volume", c.mass_ci.volume},
          {"center_of_mass", vec(c.mass_ci.center_of_mass)},
          {"principal_moments", vec(c.mass_ci.principal_moments)}}},
        {"method", c.mass_method}}},
      {"frame",
       {{"rotation", mat(c.rotation)},
        {"translation", vec(c.translation)},
        {"convention", "p_source = rotation * p_template + translation"}}},
      {"source", c.source},
      {"method", c.method},
  };
  if (!c.error.is_null()) j["error"] = c.error;
  return j;
}

ClumpTemplate clump_from_json(const json& j, const std::string& where) {
  ClumpTemplate c;
  const json& fmt = member(j, "format", where, "");
  if (!fmt.is_string() || fmt.get<std::string>() != kClumpFormat)
    throw InputError(where, "format", std::string("expected \"") + kClumpFormat + "\"");
  if (auto it = j.find("name"); it != j.end() && it->is_string()) c.name = it->get<std::string>();
  const json& sp = member(j, "spheres", where, "");
  if (!sp.is_array()) throw InputError(where, "spheres", "expected an array of [x, y, z, r]");
  for (size_t i = 0; i < sp.size(); ++i) {
    const std::string f = "spheres[" + std::to_string(i) + "]";
    if (!sp[i].is_array() || sp[i].size() != 4) throw InputError(where, f, "expected [x, y, z, r]");
    Sphere s;
    for (int k = 0; k < 3; ++k) s.center[k] = num(sp[i][k], where, f);
    s.radius = num(sp[i][3], where, f);
    c.spheres.push_back(s);
  }
  validate_spheres(c.spheres, where);
  const json& mp = member(j, "mass_properties", where, "");
  MassProperties& m = c.mass;
  m.density =
      num(member(mp, "density", where, "mass_properties"), where, "mass_properties.density");
  m.volume = num(member(mp, "volume", where, "mass_properties"), where, "mass_properties.volume");
  m.mass = num(member(mp, "mass", where, "mass_properties"), where, "mass_properties.mass");
  if (m.density <= 0) throw InputError(where, "mass_properties.density", "must be positive");
  if (m.volume <= 0) throw InputError(where, "mass_properties.volume", "must be positive");
  if (m.mass <= 0) throw InputError(where, "mass_properties.mass", "must be positive");
  m.center_of_mass = read_vec(member(mp, "center_of_mass", where, "mass_properties"), where,
                              "mass_properties.center_of_mass");
  m.inertia_tensor = read_mat(member(mp, "inertia_tensor", where, "mass_properties"), where,
                              "mass_properties.inertia_tensor");
  m.principal_moments = read_vec(member(mp, "principal_moments", where, "mass_properties"), where,
                                 "mass_properties.principal_moments");
  if ((m.principal_moments.array() <= 0).any())
    throw InputError(where, "mass_properties.principal_moments", "must be positive");
  if (auto it = mp.find("method"); it != mp.end()) {
    if (!it->is_object()) throw InputError(where, "mass_properties.method", "expected an object");
    c.mass_method = *it;
  }
  if (auto it = mp.find("basis"); it != mp.end()) c.mass_method["basis"] = *it;
  if (auto it = c.mass_method.find("basis"); it == c.mass_method.end())
    c.mass_method["basis"] = "sphere_union";  // what to_json states when none is recorded
  else if (!it->is_string())
    throw InputError(where, "mass_properties.basis", "expected a string");
  if (auto it = mp.find("ci95"); it != mp.end() && it->is_object()) {
    if (auto v = it->find("volume"); v != it->end())
      c.mass_ci.volume = num(*v, where, "mass_properties.ci95.volume");
  }
  const json& fr = member(j, "frame", where, "");
  c.rotation = read_mat(member(fr, "rotation", where, "frame"), where, "frame.rotation");
  c.translation = read_vec(member(fr, "translation", where, "frame"), where, "frame.translation");
  if (!(c.rotation * c.rotation.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-6) ||
      c.rotation.determinant() < 0)
    throw InputError(where, "frame.rotation", "is not a proper rotation matrix");
  // Provenance is free-form, but tables: commands look names up in them.
  for (const char* key : {"source", "method"})
    if (auto it = j.find(key); it != j.end() && !it->is_object())
      throw InputError(where, key, "expected an object");
  if (auto it = j.find("source"); it != j.end()) c.source = *it;
  if (auto it = j.find("method"); it != j.end()) c.method = *it;
  if (auto it = j.find("error"); it != j.end()) c.error = *it;
  return c;
}

ClumpTemplate load_clump(const std::filesystem::path& path) {
  return parse_clump(read_file(path), path.string());
}

ClumpTemplate parse_clump(const std::string& text, const std::string& where) {
  // Nesting deeper than any template needs would only make copying and printing recurse deeply.
  constexpr int kMaxDepth = 64;
  const json::parser_callback_t limit_depth = [&](int depth, json::parse_event_t, json&) {
    if (depth > kMaxDepth)
      throw InputError(where, "", "JSON nested deeper than " + std::to_string(kMaxDepth));
    return true;
  };
  json j;
  try {
    j = json::parse(text, limit_depth);
  } catch (const json::exception& e) {  // syntax errors, and numbers such as 1e999 (out_of_range)
    throw InputError(where, "", std::string("not valid JSON: ") + e.what());
  }
  return clump_from_json(j, where);
}

void save_clump(const ClumpTemplate& c, const std::filesystem::path& path) {
  write_file_atomic(path, to_json(c).dump(2) + "\n");
}

}  // namespace clumpkit
