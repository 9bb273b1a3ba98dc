#include "clumpkit/raycast/target_shape.hpp"

#include <fmt/format.h>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/core/units.hpp"
#include "clumpkit/mesh_io/load_mesh.hpp"
#include "clumpkit/raycast/analytic_surfaces.hpp"
#include "clumpkit/raycast/mesh_solid.hpp"

namespace clumpkit {

namespace fs = std::filesystem;

namespace {

// What the loader repaired, for the description: ", 3 holes closed with 41 triangles (0.8 % of
// the surface), 12 re-oriented", or nothing.
std::string repairs(const MeshReport& r) {
  std::string s;
  if (r.holes_filled > 0)
    s += fmt::format(", {} hole{} closed with {} triangles ({:.2g} % of the surface)",
                     r.holes_filled, r.holes_filled == 1 ? "" : "s", r.triangles_added,
                     r.area > 0 ? 100.0 * r.hole_area / r.area : 0.0);
  if (r.reoriented_faces > 0) s += fmt::format(", {} re-oriented", r.reoriented_faces);
  return s;
}

void note_repairs(TargetShape& t, const MeshReport& r) {
  t.reoriented_faces = r.reoriented_faces;
  t.holes_filled = r.holes_filled;
  t.hole_area_fraction = r.area > 0 ? r.hole_area / r.area : 0.0;
  t.solids = r.solids;
}

}  // namespace

TargetShape target_from_shape(const ShapeSpec& shape) {
  TargetShape t;
  t.density = shape.density;
  if (shape.kind == ShapeSpec::Kind::Cylinder) {
    t.solid = std::make_unique<CylinderSurface>(shape.diameter, shape.height);
    t.description = fmt::format("{}: cylinder D {:.6g} mm H {:.6g} mm (exact)", shape.name,
                                shape.diameter * 1e3, shape.height * 1e3);
  } else {
    MeshReport report;
    t.solid = std::make_unique<MeshSolid>(load_shape_mesh(shape, &report));
    t.description = fmt::format("{}: mesh {} ({} triangles{})", shape.name, shape.mesh.string(),
                                report.triangles, repairs(report));
    note_repairs(t, report);
  }
  return t;
}

TargetShape target_from_mesh(const fs::path& path, double scale) {
  MeshLoadOptions opt;
  opt.scale = scale;
  return target_from_mesh(path, opt);
}

TargetShape target_from_mesh(const fs::path& path, const MeshLoadOptions& opt) {
  TargetShape t;
  MeshReport report;
  TriangleMesh mesh = load_mesh(path, opt, &report);
  t.description = fmt::format("mesh {} ({} triangles{})", path.string(), mesh.triangles.size(),
                              repairs(report));
  note_repairs(t, report);
  t.solid = std::make_unique<MeshSolid>(std::move(mesh));
  return t;
}

TargetShape target_from_source(const ClumpTemplate& clump, const std::string& where) {
  const nlohmann::json& s = clump.source;
  if (!s.is_object() || s.empty())
    throw InputError(where, "source", "the template records no source shape: give --shape");
  auto str = [&](const char* key) {
    auto it = s.find(key);
    return it != s.end() && it->is_string() ? it->get<std::string>() : std::string();
  };
  double scale = 1.0;
  if (auto it = s.find("mesh_scale"); it != s.end() && it->is_number())
    scale = it->get<double>();
  else if (const std::string u = str("units"); !u.empty())
    scale = unit_factor(u, Dimension::Length, where, "source.units");
  // Relative paths are taken relative to the template's folder.
  auto resolve = [&](const fs::path& p) {
    if (p.is_absolute() || path_exists(p)) return p;
    return fs::path(where).parent_path() / p;
  };
  const std::string file = str("file"), mesh = str("mesh"), kind = str("kind");
  TargetShape t;
  if (!file.empty() && !is_mesh_file(file) && path_exists(resolve(file))) {
    t = target_from_shape(load_shape(resolve(file)));
  } else if (!mesh.empty() || (!file.empty() && is_mesh_file(file))) {
    const fs::path p = resolve(mesh.empty() ? file : mesh);
    try {
      auto flag = [&](const char* key) {
        const auto it = s.find(key);
        return it != s.end() && it->is_boolean() && it->get<bool>();
      };
      MeshLoadOptions opt;
      opt.scale = scale;
      opt.repair_orientation = flag("repair_orientation");
      opt.repair_holes = flag("repair_holes");
      t = target_from_mesh(p, opt);
    } catch (const InputError& e) {
      throw InputError(where, "source", "recorded mesh: " + std::string(e.what()));
    }
  } else if (kind == "cylinder") {
    auto num = [&](const char* key) {
      auto it = s.find(key);
      if (it == s.end() || !it->is_number() || !(it->get<double>() > 0))
        throw InputError(where, std::string("source.") + key,
                         "missing or not positive (metres); give --shape");
      return it->get<double>();
    };
    const double d = num("diameter"), h = num("height");
    t.solid = std::make_unique<CylinderSurface>(d, h);
    t.description = fmt::format("{}: cylinder D {:.6g} mm H {:.6g} mm (exact, from the template)",
                                str("shape"), d * 1e3, h * 1e3);
  } else {
    throw InputError(where, "source",
                     "names no shape file, mesh or cylinder that can be found: give --shape");
  }
  if (auto it = s.find("density"); it != s.end() && it->is_number() && t.density <= 0)
    t.density = it->get<double>();
  return t;
}

}  // namespace clumpkit
