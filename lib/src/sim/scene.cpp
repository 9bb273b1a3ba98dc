#include "clumpkit/sim/scene.hpp"

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/fill/paper_fill.hpp"
#include "clumpkit/geometry/shape_spec.hpp"
#include "clumpkit/mesh_io/load_mesh.hpp"

namespace clumpkit::sim {

namespace fs = std::filesystem;

dem::Region parse_region(const TomlDoc& doc, const std::string& key) {
  const std::string kind = doc.string(key + ".kind");
  if (kind == "box") {
    dem::BoxRegion b;
    b.min = doc.vector(key + ".min", Dimension::Length);
    b.max = doc.vector(key + ".max", Dimension::Length);
    if ((b.max.array() <= b.min.array()).any())
      doc.fail(key + ".max", "must exceed min in every coordinate");
    // cuts = [{ point = "...", normal = "..." }, ...]: the box's part on each normal's side.
    const size_t cuts = doc.array_size(key + ".cuts");
    if (cuts > dem::kMaxRegionCuts)
      doc.fail(key + ".cuts",
               std::to_string(cuts) + " planes; at most " + std::to_string(dem::kMaxRegionCuts));
    for (size_t i = 0; i < cuts; ++i) {
      const std::string c = key + ".cuts." + std::to_string(i);
      dem::HalfSpace h;
      h.point = doc.vector(c + ".point", Dimension::Length);
      h.normal = doc.vector(c + ".normal", Dimension::Dimensionless);
      if (!(h.normal.norm() > 0.0)) doc.fail(c + ".normal", "must not be zero");
      h.normal.normalize();
      b.cuts.push_back(h);
    }
    return b;
  }
  if (kind == "cylinder") {
    dem::CylinderRegion c;
    c.base_center = doc.vector(key + ".base", Dimension::Length);
    c.radius = doc.quantity(key + ".radius", Dimension::Length);
    doc.require_range(key + ".radius", c.radius, 0.0, 1e3, true);
    c.height = doc.quantity(key + ".height", Dimension::Length);
    doc.require_range(key + ".height", c.height, 0.0, 1e3, true);
    return c;
  }
  doc.fail(key + ".kind", "unknown region kind '" + kind + "' (expected box or cylinder)");
}

namespace {

fs::path resolve(const fs::path& scene, const std::string& file) {
  fs::path p(file);
  return p.is_absolute() ? p : scene.parent_path() / p;
}

dem::ClumpTypeSettings parse_clump(const TomlDoc& doc, const std::string& key, const fs::path& path,
                                   const fs::path& data_dir) {
  dem::ClumpTypeSettings t;
  t.name = doc.string(key + ".name");
  t.material = doc.string_opt(key + ".material").value_or("pill");
  const bool has_template = doc.has(key + ".template"), has_shape = doc.has(key + ".shape");
  if (has_template == has_shape)
    doc.fail(key, "give exactly one of 'template' (a clump JSON) or 'shape' + 'spheres'");
  if (has_template) {
    t.clump = load_clump(resolve(path, doc.string(key + ".template")));
  } else {
    std::string shape = doc.string(key + ".shape");
    fs::path sp = resolve(path, shape);
    if (!path_exists(sp)) sp = data_dir / "shapes" / (shape + ".toml");
    if (!path_exists(sp)) doc.fail(key + ".shape", "no shape file '" + shape + "'");
    PaperFillRequest req;
    req.spheres = static_cast<int>(doc.integer(key + ".spheres"));
    try {
      t.clump = paper_fill_template(load_shape(sp), req);
    } catch (const InputError& e) {
      doc.fail(key + ".spheres", e.message());
    }
  }
  return t;
}

dem::WallSettings parse_wall(const TomlDoc& doc, const std::string& key, const fs::path& path) {
  dem::WallSettings w;
  w.name = doc.string(key + ".name");
  w.material = doc.string(key + ".material");
  if (doc.has(key + ".mesh")) {
    MeshLoadOptions o;
    o.scale = unit_factor(doc.string_opt(key + ".units").value_or("m"), Dimension::Length,
                          doc.name(), key + ".units");
    o.require_closed = false;  // walls are surfaces: an open cup is fine
    o.check_self_intersections = false;
    TriangleMesh m;
    try {
      m = load_mesh(resolve(path, doc.string(key + ".mesh")), o);
    } catch (const InputError& e) {
      doc.fail(key + ".mesh", e.what());
    }
    w.mesh.vertices = m.vertices;
    for (const auto& tri : m.triangles) w.mesh.triangles.push_back({tri[0], tri[1], tri[2]});
  } else {
    const std::string prim = doc.string(key + ".primitive");
    if (prim == "plane") {
      w.mesh = dem::make_plane(doc.vector(key + ".center", Dimension::Length),
                               doc.vector(key + ".normal", Dimension::Dimensionless),
                               doc.quantity(key + ".size_u", Dimension::Length),
                               doc.quantity(key + ".size_v", Dimension::Length),
                               static_cast<int>(doc.integer_opt(key + ".divisions").value_or(1)));
    } else if (prim == "cylinder") {
      w.mesh = dem::make_cylinder(doc.vector(key + ".base", Dimension::Length),
                                  doc.quantity(key + ".radius", Dimension::Length),
                                  doc.quantity(key + ".height", Dimension::Length),
                                  static_cast<int>(doc.integer_opt(key + ".segments").value_or(64)),
                                  doc.boolean_opt(key + ".bottom").value_or(true),
                                  doc.boolean_opt(key + ".top").value_or(false));
    } else if (prim == "box") {
      w.mesh = dem::make_box(doc.vector(key + ".min", Dimension::Length),
                             doc.vector(key + ".max", Dimension::Length));
    } else {
      doc.fail(key + ".primitive",
               "unknown primitive '" + prim + "' (expected plane, cylinder or box; or give mesh)");
    }
  }
  const std::string m = key + ".motion";
  if (auto v = doc.vector_opt(m + ".velocity", Dimension::Velocity)) {
    const double start = doc.quantity_opt(m + ".start", Dimension::Time).value_or(0.0);
    const double stop = doc.quantity_opt(m + ".stop", Dimension::Time)
                            .value_or(std::numeric_limits<double>::infinity());
    if (stop <= start) doc.fail(m + ".stop", "must be after start");
    dem::VelocityProfile p;
    // Step profile: at rest until start, moving until stop (short ramps of 1 ms keep it piecewise
    // linear and avoid infinite accelerations).
    const double ramp = 1e-3;
    p.times = {start, start + ramp};
    p.velocities = {Eigen::Vector3d::Zero(), *v};
    if (std::isfinite(stop)) {
      p.times.push_back(stop);
      p.velocities.push_back(*v);
      p.times.push_back(stop + ramp);
      p.velocities.push_back(Eigen::Vector3d::Zero());
    }
    w.motion.translation = p;
  }
  if (auto rpm = doc.number_opt(m + ".rpm")) {
    dem::WallRotation r;
    r.rpm = *rpm;
    r.axis =
        doc.vector_opt(m + ".axis", Dimension::Dimensionless).value_or(Eigen::Vector3d::UnitZ());
    if (r.axis.norm() == 0) doc.fail(m + ".axis", "must not be zero");
    r.axis_point =
        doc.vector_opt(m + ".axis_point", Dimension::Length).value_or(Eigen::Vector3d::Zero());
    r.start_time = doc.quantity_opt(m + ".start", Dimension::Time).value_or(0.0);
    w.motion.rotation = r;
  }
  return w;
}

dem::FactorySettings parse_factory(const TomlDoc& doc, const std::string& key) {
  dem::FactorySettings f;
  f.name = doc.string_opt(key + ".name").value_or("factory");
  f.region = parse_region(doc, key + ".region");
  const bool has_count = doc.has(key + ".count"), has_mass = doc.has(key + ".mass");
  if (has_count == has_mass) doc.fail(key, "give exactly one of 'count' and 'mass'");
  if (has_count) {
    f.count = doc.integer(key + ".count");
    if (*f.count <= 0) doc.fail(key + ".count", "must be positive");
  } else {
    f.mass = doc.quantity(key + ".mass", Dimension::Mass);
    doc.require_range(key + ".mass", *f.mass, 0.0, 1e6, true);
  }
  if (doc.has(key + ".rate")) {
    f.rate =
        has_count ? doc.number(key + ".rate") : doc.quantity(key + ".rate", Dimension::MassFlow);
    doc.require_range(key + ".rate", f.rate, 0.0, 1e9, true);
  }
  f.start_time = doc.quantity_opt(key + ".start", Dimension::Time).value_or(0.0);
  f.velocity =
      doc.vector_opt(key + ".velocity", Dimension::Velocity).value_or(Eigen::Vector3d::Zero());
  f.random_orientation = doc.boolean_opt(key + ".random_orientation").value_or(true);
  f.whole_in_region = doc.boolean_opt(key + ".whole_in_region").value_or(true);
  const size_t n = doc.array_size(key + ".mixture");
  if (n == 0) doc.fail(key + ".mixture", "missing: list of {clump = NAME, fraction = F}");
  for (size_t i = 0; i < n; ++i) {
    const std::string e = key + ".mixture." + std::to_string(i);
    dem::MixtureEntry m;
    m.clump_type = doc.string(e + ".clump");
    m.mass_fraction = doc.number_opt(e + ".fraction").value_or(1.0);
    doc.require_range(e + ".fraction", m.mass_fraction, 0.0, 1.0, true);
    f.mixture.push_back(m);
  }
  return f;
}

}  // namespace

Scene load_scene(const fs::path& path, const fs::path& data_dir) {
  TomlDoc doc = TomlDoc::load(path);
  Scene s;
  s.path = path;
  dem::WorldSettings& w = s.world;
  w.source = path.string();
  const std::string mat = doc.string_opt("simulation.materials").value_or("");
  w.materials = MaterialLibrary::load(mat.empty() ? data_dir / "shapes" / "materials.toml"
                                                  : resolve(path, mat));
  if (auto rm = doc.string_opt("simulation.rolling_model"))
    w.rolling_model = dem::rolling_model_from_string(*rm, doc.name(), "simulation.rolling_model");
  s.until = doc.quantity("simulation.until", Dimension::Time);
  doc.require_range("simulation.until", s.until, 0.0, 1e6, true);
  if (auto g = doc.vector_opt("simulation.gravity", Dimension::Acceleration)) w.gravity = *g;
  if (auto ts = doc.string_opt("simulation.time_step"); ts && *ts != "auto") {
    w.time_step = doc.quantity("simulation.time_step", Dimension::Time);
    doc.require_range("simulation.time_step", w.time_step, 0.0, 1.0, true);
  }
  if (auto rf = doc.number_opt("simulation.rayleigh_fraction")) {
    w.rayleigh_fraction = *rf;
    doc.require_range("simulation.rayleigh_fraction", *rf, 0.0, 1.0, true);
  }
  if (auto id = doc.boolean_opt("simulation.implicit_damping"))
    w.implicit_damping = *id ? dem::kImplicitDampingGate : 0.0;
  if (auto v = doc.quantity_opt("simulation.max_impact_speed", Dimension::Velocity))
    w.max_impact_speed = *v;
  if (auto seed = doc.integer_opt("simulation.seed")) {
    if (*seed < 0) doc.fail("simulation.seed", "must not be negative");
    w.seed = static_cast<std::uint64_t>(*seed);
  }
  if (auto th = doc.integer_opt("simulation.threads")) w.threads = static_cast<int>(*th);

  s.output.every = doc.quantity_opt("output.every", Dimension::Time).value_or(s.until / 50.0);
  doc.require_range("output.every", s.output.every, 0.0, 1e6, true);
  s.output.vtk = doc.boolean_opt("output.vtk").value_or(true);
  s.output.checkpoint_minutes = doc.number_opt("output.checkpoint_minutes").value_or(5.0);
  doc.require_range("output.checkpoint_minutes", s.output.checkpoint_minutes, 0.0, 1e6, true);

  const size_t nc = doc.array_size("clumps");
  if (nc == 0) throw InputError(path.string(), "clumps", "no clump types ([[clumps]] tables)");
  for (size_t i = 0; i < nc; ++i)
    w.clump_types.push_back(parse_clump(doc, "clumps." + std::to_string(i), path, data_dir));
  for (size_t i = 0; i < doc.array_size("walls"); ++i)
    w.walls.push_back(parse_wall(doc, "walls." + std::to_string(i), path));
  for (size_t i = 0; i < doc.array_size("factories"); ++i)
    w.factories.push_back(parse_factory(doc, "factories." + std::to_string(i)));
  for (size_t i = 0; i < doc.array_size("regions"); ++i) {
    const std::string k = "regions." + std::to_string(i);
    s.regions.push_back({doc.string(k + ".name"), parse_region(doc, k)});
  }
  return s;
}

}  // namespace clumpkit::sim
