#include "clumpkit/rigs/model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/core/toml_doc.hpp"
#include "clumpkit/fill/fill_problem.hpp"
#include "clumpkit/fill/paper_fill.hpp"
#include "clumpkit/geometry/mass_properties.hpp"
#include "clumpkit/raycast/target_shape.hpp"

namespace clumpkit {

namespace fs = std::filesystem;

const std::vector<std::string>& effect_names() {
  static const std::vector<std::string> n = {
      "rolling_friction", "particle_friction", "wall_friction",     "restitution",
      "cohesion",         "shape_resolution",  "size_distribution", "rolling_model"};
  return n;
}

void check_effect_name(const std::string& name, const std::string& where,
                       const std::string& field) {
  const auto& n = effect_names();
  if (std::find(n.begin(), n.end(), name) != n.end()) return;
  std::string known;
  for (const auto& e : n) known += (known.empty() ? "" : ", ") + e;
  throw InputError(where, field, "unknown effect '" + name + "' (known: " + known + ")");
}

const char* to_string(MassBasis b) {
  switch (b) {
    case MassBasis::kSphereUnion:
      return "sphere_union";
    case MassBasis::kTrueShape:
      return "true_shape";
    case MassBasis::kGiven:
      return "given";
  }
  return "?";
}

bool ModelEffects::on(const std::string& e) const {
  if (e == "rolling_friction") return rolling_friction.has_value();
  if (e == "particle_friction") return particle_friction.has_value();
  if (e == "wall_friction") return wall_friction.has_value();
  if (e == "restitution") return restitution.has_value();
  if (e == "cohesion") return cohesion.has_value();
  if (e == "shape_resolution") return shape_resolution.has_value();
  if (e == "size_distribution") return size_distribution;
  if (e == "rolling_model") return rolling_model.has_value();
  return false;
}

namespace {

// A relative path: next to the file that names it, else in the bundled data folder.
fs::path resolve(const fs::path& p, const fs::path& base, const fs::path& data_dir) {
  if (p.is_absolute()) return p;
  const fs::path local = base / p;
  if (path_exists(local) || data_dir.empty()) return local;
  const fs::path bundled = data_dir / p;
  return path_exists(bundled) ? bundled : local;
}

// Per-partner values "pill = 0.08", "abs_plastic = 0.12" of an effect table; `defaults` fills
// the partners the file does not give.
std::map<std::string, double> partner_values(const TomlDoc& doc, const std::string& table,
                                             const std::set<std::string>& reserved, double lo,
                                             double hi, bool lo_open) {
  std::map<std::string, double> out;
  for (const auto& k : doc.keys(table)) {
    if (reserved.count(k)) continue;
    const std::string key = table + "." + k;
    const double v = doc.number(key);
    doc.require_range(key, v, lo, hi, lo_open, false);
    out[k] = v;
  }
  return out;
}

// Why a height spread cannot split this model's types into height classes refilled by the paper
// rule; "" when it can.
std::string height_spread_blocker(const ParticleModel& m) {
  for (const ModelType& t : m.types) {
    if (t.shape.kind != ShapeSpec::Kind::Cylinder)
      return "a height spread needs cylinder shapes (type " + t.name + " is a mesh)";
    if (!t.paper_spheres)
      return "a height spread refills each height class by the paper rule (type " + t.name +
             " uses a clump template)";
  }
  return "";
}

// Why shape_resolution cannot fill this model's clump-template types again (a mesh shape whose
// file is not there); "" when it can. Checked where the effect is set, so a run is refused before
// it starts and a diagnosis skips the candidate with the reason.
std::string shape_resolution_blocker(const ParticleModel& m) {
  for (const ModelType& t : m.types)
    if (!t.paper_spheres && t.shape.kind == ShapeSpec::Kind::Mesh && !path_exists(t.shape.mesh))
      return "type " + t.name + " is filled again from its shape's mesh '" + t.shape.mesh.string() +
             "' (shape file " + t.shape_path.string() + "), which is not there";
  return "";
}

// Effect tables are either `name = true` / `name = false` or a table `[effects.name]`.
bool effect_listed(const TomlDoc& doc, const std::string& e, bool& as_table) {
  const std::string key = "effects." + e;
  as_table = false;
  if (!doc.has(key)) return false;
  try {
    doc.keys(key);  // throws unless a table
    as_table = true;
    return true;
  } catch (const InputError&) {
    return *doc.boolean_opt(key);  // throws "expected true or false" for anything else
  }
}

double interaction_or(const MaterialLibrary& lib, const std::string& other,
                      double Interaction::*field, const std::string& where) {
  return lib.interaction("pill", other, where).*field;
}

}  // namespace

ParticleModel parse_model(const std::string& text, const fs::path& path, const fs::path& data_dir) {
  const TomlDoc doc = TomlDoc::parse(text, path.string());
  const std::string where = path.string();
  const fs::path base = path.has_parent_path() ? path.parent_path() : fs::path(".");

  // Unknown top-level tables are typos: refuse them.
  for (const auto& k : doc.keys("")) {
    static const std::set<std::string> known = {"model", "types", "effects"};
    if (!known.count(k)) doc.fail(k, "unknown section (known: model, types, effects)");
  }

  ParticleModel m;
  m.path = path;
  m.name = doc.string_opt("model.name").value_or(path.stem().string());
  m.description = doc.string_opt("model.description").value_or("");
  if (auto mp = doc.string_opt("model.materials")) {
    m.materials_path = resolve(*mp, base, data_dir);
    try {
      m.materials = MaterialLibrary::load(m.materials_path);
    } catch (const InputError& e) {
      if (!path_exists(m.materials_path))
        doc.fail("model.materials", "file '" + *mp + "' not found");
      throw;
    }
  }
  if (!m.materials.has("pill")) doc.fail("model.materials", "the library has no material 'pill'");
  const std::string basis = doc.string_opt("model.mass_basis").value_or("sphere_union");
  if (basis == "sphere_union")
    m.mass_basis = MassBasis::kSphereUnion;
  else if (basis == "true_shape")
    m.mass_basis = MassBasis::kTrueShape;
  else if (basis == "given")
    m.mass_basis = MassBasis::kGiven;
  else
    doc.fail("model.mass_basis", "'" + basis + "' is not one of: sphere_union, true_shape, given");

  // Types.
  const size_t nt = doc.array_size("types");
  if (nt == 0) doc.fail("types", "a model needs at least one [[types]] entry");
  double fsum = 0.0;
  std::set<std::string> names;
  for (size_t i = 0; i < nt; ++i) {
    const std::string p = "types." + std::to_string(i) + ".";
    for (const auto& k : doc.keys("types." + std::to_string(i))) {
      static const std::set<std::string> known = {"name",  "shape",         "paper_spheres",
                                                  "clump", "mass_fraction", "mass"};
      if (!known.count(k))
        doc.fail(p + k,
                 "unknown key (known: name, shape, paper_spheres, clump, mass_fraction, mass)");
    }
    ModelType t;
    t.name = doc.string(p + "name");
    if (t.name.empty() || !names.insert(t.name).second)
      doc.fail(p + "name", "type names must be non-empty and unique");
    if (!doc.has(p + "shape"))
      doc.fail(p + "shape",
               "missing: every type needs a shape file (its outline, kind = \"cylinder\" or "
               "\"mesh\", its material and density), also a type given as a clump template");
    const std::string shape = doc.string(p + "shape");
    t.shape_path = resolve(shape, base, data_dir);
    if (!path_exists(t.shape_path)) doc.fail(p + "shape", "file '" + shape + "' not found");
    t.shape = load_shape(t.shape_path);
    const bool has_rule = doc.has(p + "paper_spheres"), has_clump = doc.has(p + "clump");
    if (has_rule == has_clump)
      doc.fail(p + (has_rule ? "clump" : "paper_spheres"),
               "give exactly one of paper_spheres (the paper's rule) and clump (a template file)");
    if (has_rule) {
      const long long n = doc.integer(p + "paper_spheres");
      doc.require_range(p + "paper_spheres", double(n), 1, 1000);
      t.paper_spheres = int(n);
    } else {
      const std::string c = doc.string(p + "clump");
      t.clump_path = resolve(c, base, data_dir);
      if (!path_exists(t.clump_path)) doc.fail(p + "clump", "file '" + c + "' not found");
    }
    t.mass_fraction = doc.number_opt(p + "mass_fraction").value_or(t.shape.mass_fraction);
    doc.require_range(p + "mass_fraction", t.mass_fraction, 0.0, 1.0, true, false);
    if (m.mass_basis == MassBasis::kGiven) {
      if (!doc.has(p + "mass"))
        doc.fail(p + "mass", "mass_basis = \"given\" needs a mass per pill");
      t.given_mass = doc.quantity(p + "mass", Dimension::Mass);
      doc.require_range(p + "mass", *t.given_mass, 0.0, 1e3, true, false);
    } else if (doc.has(p + "mass")) {
      doc.fail(p + "mass", "a given mass needs model.mass_basis = \"given\"");
    }
    fsum += t.mass_fraction;
    m.types.push_back(std::move(t));
  }
  for (auto& t : m.types) t.mass_fraction /= fsum;

  // Effects.
  for (const auto& k : doc.keys("effects")) check_effect_name(k, where, "effects." + k);
  ModelEffects& fx = m.effects;
  const MaterialLibrary& lib = m.materials;
  bool tbl = false;
  auto walls_of = [&]() {
    std::vector<std::string> w;
    for (const auto& n : lib.names())
      if (n != "pill" && lib.has_interaction("pill", n)) w.push_back(n);
    return w;
  };
  auto check_partners = [&](const std::string& table, const std::map<std::string, double>& vals,
                            bool walls_only) {
    for (const auto& [k, v] : vals) {
      if (!lib.has(k) || !lib.has_interaction("pill", k))
        doc.fail(table + "." + k, "no material '" + k + "' interacting with 'pill' in the library");
      if (walls_only && k == "pill")
        doc.fail(table + "." + k, "pill–pill friction is the effect particle_friction");
    }
  };
  if (effect_listed(doc, "rolling_friction", tbl)) {
    std::map<std::string, double> v;
    if (tbl) v = partner_values(doc, "effects.rolling_friction", {}, 0.0, 10.0, false);
    check_partners("effects.rolling_friction", v, false);
    for (const auto& w : walls_of())
      if (!v.count(w)) v[w] = interaction_or(lib, w, &Interaction::rolling_friction, where);
    if (!v.count("pill"))
      v["pill"] = interaction_or(lib, "pill", &Interaction::rolling_friction, where);
    fx.rolling_friction = v;
  }
  if (effect_listed(doc, "particle_friction", tbl)) {
    double v = interaction_or(lib, "pill", &Interaction::static_friction, where);
    if (tbl) {
      for (const auto& k : doc.keys("effects.particle_friction"))
        if (k != "value") doc.fail("effects.particle_friction." + k, "unknown key (known: value)");
      if (auto x = doc.number_opt("effects.particle_friction.value")) {
        doc.require_range("effects.particle_friction.value", *x, 0.0, 10.0);
        v = *x;
      }
    }
    fx.particle_friction = v;
  }
  if (effect_listed(doc, "wall_friction", tbl)) {
    std::map<std::string, double> v;
    if (tbl) v = partner_values(doc, "effects.wall_friction", {}, 0.0, 10.0, false);
    check_partners("effects.wall_friction", v, true);
    for (const auto& w : walls_of())
      if (!v.count(w)) v[w] = interaction_or(lib, w, &Interaction::static_friction, where);
    fx.wall_friction = v;
  }
  if (effect_listed(doc, "restitution", tbl)) {
    std::map<std::string, double> v;
    if (tbl) v = partner_values(doc, "effects.restitution", {}, 0.0, 1.0, true);
    check_partners("effects.restitution", v, false);
    for (const auto& w : walls_of())
      if (!v.count(w)) v[w] = interaction_or(lib, w, &Interaction::restitution, where);
    if (!v.count("pill")) v["pill"] = interaction_or(lib, "pill", &Interaction::restitution, where);
    fx.restitution = v;
  }
  if (effect_listed(doc, "cohesion", tbl)) {
    if (!tbl || !doc.has("effects.cohesion.energy_density"))
      doc.fail("effects.cohesion", "cohesion needs energy_density, e.g. \"2e4 J/m^3\"");
    for (const auto& k : doc.keys("effects.cohesion"))
      if (k != "energy_density")
        doc.fail("effects.cohesion." + k, "unknown key (known: energy_density)");
    const double k = doc.quantity("effects.cohesion.energy_density", Dimension::Pressure);
    doc.require_range("effects.cohesion.energy_density", k, 0.0, 1e12);
    fx.cohesion = k;
  }
  if (effect_listed(doc, "shape_resolution", tbl)) {
    if (!tbl || !doc.has("effects.shape_resolution.spheres"))
      doc.fail("effects.shape_resolution",
               "shape_resolution needs spheres = N (the paper rule's count for a paper-rule "
               "type; a type given as a clump template is filled again by the optimiser)");
    const long long n = doc.integer("effects.shape_resolution.spheres");
    doc.require_range("effects.shape_resolution.spheres", double(n), 1, 1000);
    fx.shape_resolution = int(n);
    if (const std::string why = shape_resolution_blocker(m); !why.empty())
      doc.fail("effects.shape_resolution", why);
  }
  fx.size_distribution = effect_listed(doc, "size_distribution", tbl);
  if (m.types.size() > 1 && !fx.size_distribution)
    doc.fail("effects",
             "a model with several types needs effects.size_distribution = true "
             "(without it the population has one size)");
  if (fx.size_distribution && tbl) {
    const std::string key = "effects.size_distribution.height_spread";
    for (const auto& k : doc.keys("effects.size_distribution"))
      if (k != "height_spread")
        doc.fail("effects.size_distribution." + k,
                 "unknown key (known: height_spread; the fractions are the types' "
                 "mass_fraction)");
    if (auto s = doc.number_opt(key)) {
      doc.require_range(key, *s, 0.0, kMaxHeightSpread);
      fx.height_spread = *s;
      if (const std::string why = height_spread_blocker(m); *s > 0 && !why.empty())
        doc.fail(key, why);
    }
  }
  if (effect_listed(doc, "rolling_model", tbl)) {
    if (!tbl || !doc.has("effects.rolling_model.model"))
      doc.fail("effects.rolling_model",
               "rolling_model needs model = \"standard\", \"cdt\" or \"epsd\"");
    for (const auto& k : doc.keys("effects.rolling_model"))
      if (k != "model" && k != "viscous_damping")
        doc.fail("effects.rolling_model." + k, "unknown key (known: model, viscous_damping)");
    fx.rolling_model = dem::rolling_model_from_string(doc.string("effects.rolling_model.model"),
                                                      where, "effects.rolling_model.model");
    if (auto d = doc.number_opt("effects.rolling_model.viscous_damping")) {
      doc.require_range("effects.rolling_model.viscous_damping", *d, 0.0, 10.0);
      fx.epsd_damping = *d;
    }
    if (!fx.rolling_friction)
      doc.fail("effects.rolling_model", "a rolling model needs effects.rolling_friction on");
  }
  return m;
}

ParticleModel load_model(const fs::path& path, const fs::path& data_dir) {
  if (!path_exists(path)) throw InputError(path.string(), "", "model file not found");
  return parse_model(read_file(path), path, data_dir);
}

std::vector<ModelType> ParticleModel::population() const {
  if (!effects.size_distribution || effects.height_spread <= 0) return types;
  if (const std::string why = height_spread_blocker(*this); !why.empty())
    throw InputError(path.string(), "effects.size_distribution.height_spread", why);
  // Three-point Gauss–Hermite classes of the mass-weighted height distribution.
  struct HeightClass {
    const char* suffix;
    double z, fraction;
  };
  const double z = std::sqrt(3.0);
  const HeightClass classes[] = {
      {"_short", -z, 1.0 / 6}, {"", 0.0, 2.0 / 3}, {"_tall", z, 1.0 / 6}};
  std::vector<ModelType> out;
  for (const ModelType& t : types)
    for (const HeightClass& k : classes) {
      ModelType c = t;
      c.name = t.name + k.suffix;
      c.height_factor = 1.0 + effects.height_spread * k.z;
      c.shape.height *= c.height_factor;
      c.mass_fraction = t.mass_fraction * k.fraction;
      if (c.given_mass) *c.given_mass *= c.height_factor;  // one diameter: mass in proportion
      out.push_back(std::move(c));
    }
  return out;
}

namespace {

// A type given as a clump template, at another sphere count (shape_resolution): its shape (a
// mesh or a cylinder) filled again by the optimiser (`clumpkit fill SHAPE --method optimal
// --spheres N`, one thread, seed 1), at the shape file's density. The same model gives the same
// clump bits.
ClumpTemplate refill_template_type(const ModelType& t, int spheres, long rays) {
  TargetShape target = target_from_shape(t.shape);
  std::shared_ptr<const SurfaceSolid> solid(std::move(target.solid));
  const FillShape shape = fill_shape_with_surface_distance(solid, t.shape_path.string());
  FillOptions o;
  o.spheres = spheres;
  o.threads = 1;  // the rig runs of a diagnosis already run side by side
  validate_fill_options(o);
  const FillResult r = optimal_fill(shape, o);
  RaySamplingOptions sampling;
  sampling.rays = rays;
  sampling.seed = o.seed + 7919;  // as `clumpkit fill`: independent of the fill's own rays
  ClumpTemplate c = fill_template("optimal", o, r, measure_fill(shape, r.spheres, sampling),
                                  t.shape.density, sampling);
  c.source = {{"file", t.shape_path.string()}};
  return c;
}

}  // namespace

std::vector<dem::ClumpTypeSettings> ParticleModel::clump_types(long rays) const {
  std::vector<dem::ClumpTypeSettings> out;
  for (const ModelType& t : population()) {
    ClumpTemplate c;
    if (effects.shape_resolution && !t.paper_spheres && !t.clump_path.empty()) {
      c = refill_template_type(t, *effects.shape_resolution, rays);
    } else if (t.paper_spheres) {
      PaperFillRequest req;
      req.spheres = effects.shape_resolution ? *effects.shape_resolution : *t.paper_spheres;
      // A height class keeps its type's rule (the regime of the type's own height).
      if (t.height_factor != 1.0) {
        const double h = t.shape.height / t.height_factor;
        try {
          req.custom = paper_preset(regime(t.shape.diameter, h), req.spheres);
        } catch (const InputError& e) {
          throw e.at(t.shape_path.string());
        }
      }
      req.sampling.rays = rays;
      c = paper_fill_template(t.shape, req);
    } else {
      c = load_clump(t.clump_path);
    }
    // Mass basis: scale mass and inertia together (the union's mass distribution is kept).
    // The union's mass is its volume at the density of the type's shape file, also for a
    // template filled at another density (`clumpkit fill` defaults to 1380 kg/m^3).
    double target = c.mass.mass;
    if (mass_basis == MassBasis::kSphereUnion && c.mass.density > 0.0 &&
        c.mass.density != t.shape.density) {
      target = c.mass.mass / c.mass.density * t.shape.density;
    } else if (mass_basis == MassBasis::kTrueShape) {
      if (t.shape.kind != ShapeSpec::Kind::Cylinder)
        throw InputError(path.string(), "model.mass_basis",
                         "true_shape needs cylinder shapes (type " + t.name + ")");
      target = t.shape.density * M_PI * 0.25 * t.shape.diameter * t.shape.diameter * t.shape.height;
    } else if (mass_basis == MassBasis::kGiven) {
      target = *t.given_mass;
    }
    const double f = target / c.mass.mass;
    c.mass.mass *= f;
    c.mass.density *= f;
    c.mass.inertia_tensor *= f;
    c.mass.principal_moments *= f;
    c.mass_method["mass_basis"] = to_string(mass_basis);
    c.mass_method["mass_scale"] = f;
    c.name = t.name;
    out.push_back({t.name, std::move(c), "pill"});
  }
  return out;
}

std::vector<dem::PairContactOverride> ParticleModel::pair_contacts(
    const std::vector<std::string>& wall_materials) const {
  std::vector<dem::PairContactOverride> out;
  const dem::RollingModel rm = effects.rolling_model.value_or(dem::RollingModel::kStandard);
  auto law_for = [&](const std::string& other) {
    dem::PairContact law;
    const bool wall = other != "pill";
    if (effects.restitution) law.restitution = effects.restitution->at(other);
    if (wall && effects.wall_friction) law.static_friction = effects.wall_friction->at(other);
    if (!wall && effects.particle_friction) law.static_friction = *effects.particle_friction;
    if (effects.rolling_friction) {
      dem::RollingFriction r;
      r.model = rm;
      r.coefficient = effects.rolling_friction->at(other);
      r.viscous_damping = effects.epsd_damping;
      law.rolling = r;
    }
    if (!wall && effects.cohesion) law.cohesion = dem::Cohesion{*effects.cohesion};
    return law;
  };
  out.push_back({"pill", "pill", law_for("pill")});
  std::set<std::string> done;
  for (const auto& w : wall_materials) {
    if (!done.insert(w).second) continue;
    if (!materials.has(w) || !materials.has_interaction("pill", w))
      throw InputError(path.string(), "model.materials",
                       "the library has no material '" + w + "' interacting with the pill");
    // Effects whose per-partner map lacks this wall (a library loaded later): library value.
    dem::PairContact law = law_for(w);
    out.push_back({"pill", w, law});
  }
  return out;
}

void ParticleModel::configure(dem::WorldSettings& ws, const std::vector<std::string>& walls,
                              long rays) const {
  ws.source = path.string();
  ws.materials = materials;
  ws.rolling_model = effects.rolling_model.value_or(dem::RollingModel::kStandard);
  ws.clump_types = clump_types(rays);
  ws.pair_contacts = pair_contacts(walls);
}

std::vector<dem::MixtureEntry> ParticleModel::mixture() const {
  std::vector<dem::MixtureEntry> m;
  for (const auto& t : population()) m.push_back({t.name, t.mass_fraction});
  return m;
}

std::string ParticleModel::summary() const {
  std::string s = fmt::format("model {} ({} basis):", name, to_string(mass_basis));
  for (const auto& t : types)
    s +=
        fmt::format(" {} {:.0f}% {}", t.name, 100.0 * t.mass_fraction,
                    effects.shape_resolution ? fmt::format("{}-sphere{}", *effects.shape_resolution,
                                                           t.paper_spheres ? "" : " (optimiser)")
                    : t.paper_spheres        ? fmt::format("{}-sphere", *t.paper_spheres)
                                             : t.clump_path.filename().string());
  s += "; effects on:";
  for (const auto& e : effect_names())
    if (effects.on(e)) s += " " + e;
  if (effects.size_distribution && effects.height_spread > 0)
    s += fmt::format(" (height spread {:.3g})", effects.height_spread);
  return s;
}

namespace {

double parse_number(const std::string& v, const std::string& where, const std::string& key,
                    double lo, double hi) {
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != 0 || !std::isfinite(x) || x < lo || x > hi)
    throw InputError(where, key, fmt::format("'{}' is not a number in [{}, {}]", v, lo, hi));
  return x;
}

}  // namespace

void set_model_effect(ParticleModel& m, const std::string& key, const std::string& value,
                      const std::string& where) {
  // key: effects.NAME[.PARTNER]
  if (key.rfind("effects.", 0) != 0)
    throw InputError(where, key, "expected effects.NAME[.PARTNER]=VALUE or effects.NAME=off");
  const std::string rest = key.substr(8);
  const auto dot = rest.find('.');
  const std::string name = rest.substr(0, dot);
  const std::string partner = dot == std::string::npos ? "" : rest.substr(dot + 1);
  check_effect_name(name, where, key);
  ModelEffects& fx = m.effects;
  const MaterialLibrary& lib = m.materials;
  if (value == "off") {
    if (!partner.empty()) throw InputError(where, key, "'off' switches a whole effect off");
    if (name == "rolling_friction") fx.rolling_friction.reset(), fx.rolling_model.reset();
    if (name == "particle_friction") fx.particle_friction.reset();
    if (name == "wall_friction") fx.wall_friction.reset();
    if (name == "restitution") fx.restitution.reset();
    if (name == "cohesion") fx.cohesion.reset();
    if (name == "shape_resolution") fx.shape_resolution.reset();
    if (name == "rolling_model") fx.rolling_model.reset();
    if (name == "size_distribution") {
      if (m.types.size() > 1)
        throw InputError(where, key, "the model has several types; edit the model file instead");
      fx.size_distribution = false;
      fx.height_spread = 0.0;
    }
    return;
  }
  auto partners_default = [&](double Interaction::*field, bool with_pill) {
    std::map<std::string, double> v;
    for (const auto& n : lib.names())
      if ((n != "pill" || with_pill) && lib.has_interaction("pill", n))
        v[n] = lib.interaction("pill", n).*field;
    return v;
  };
  auto set_partner = [&](std::optional<std::map<std::string, double>>& slot,
                         double Interaction::*field, bool with_pill, double lo, double hi) {
    if (!slot) slot = partners_default(field, with_pill);
    if (value == "on") return;
    const double x = parse_number(value, where, key, lo, hi);
    if (partner.empty()) {
      for (auto& [k, v] : *slot) v = x;
    } else {
      if (!slot->count(partner))
        throw InputError(where, key, "no partner material '" + partner + "'");
      (*slot)[partner] = x;
    }
  };
  if (name == "rolling_friction") {
    set_partner(fx.rolling_friction, &Interaction::rolling_friction, true, 0.0, 10.0);
  } else if (name == "wall_friction") {
    set_partner(fx.wall_friction, &Interaction::static_friction, false, 0.0, 10.0);
  } else if (name == "restitution") {
    set_partner(fx.restitution, &Interaction::restitution, true, 1e-6, 1.0);
  } else if (name == "particle_friction") {
    fx.particle_friction = value == "on" ? lib.interaction("pill", "pill").static_friction
                                         : parse_number(value, where, key, 0.0, 10.0);
  } else if (name == "cohesion") {
    fx.cohesion = parse_quantity(value, Dimension::Pressure, where, key);
  } else if (name == "shape_resolution") {
    const int n = int(parse_number(value, where, key, 1, 1000));
    if (const std::string why = shape_resolution_blocker(m); !why.empty())
      throw InputError(where, key, why);
    fx.shape_resolution = n;
  } else if (name == "size_distribution") {
    // "on", or a number: the height spread (effects.size_distribution=0.05 or
    // effects.size_distribution.height_spread=0.05); effects.size_distribution.TYPE=0.5: that
    // type's mass fraction, the other types sharing the rest in their ratios.
    if (!partner.empty() && partner != "height_spread") {
      auto it = std::find_if(m.types.begin(), m.types.end(),
                             [&](const ModelType& t) { return t.name == partner; });
      if (it == m.types.end() || m.types.size() < 2) {
        std::string names;
        for (const auto& t : m.types) names += (names.empty() ? "" : ", ") + t.name;
        throw InputError(where, key,
                         m.types.size() < 2
                             ? "size_distribution's parameters: height_spread, or a type's mass "
                               "fraction in a model of several types (this one has one: " +
                                   names + ")"
                             : "size_distribution's parameters: height_spread, or the mass "
                               "fraction of a type (" +
                                   names + ")");
      }
      const double x = parse_number(value, where, key, 0.0, 1.0);
      if (x <= 0.0 || x >= 1.0)
        throw InputError(where, key,
                         "a type's mass fraction is between 0 and 1 (exclusive: every type of "
                         "the model keeps some mass)");
      const double others = 1.0 - it->mass_fraction;  // > 0: every type holds some mass
      for (auto& t : m.types)
        t.mass_fraction = &t == &*it ? x : t.mass_fraction * (1.0 - x) / others;
      fx.size_distribution = true;
      return;
    }
    double spread = fx.size_distribution ? fx.height_spread : 0.0;
    if (value != "on") spread = parse_number(value, where, key, 0.0, kMaxHeightSpread);
    if (spread > 0)
      if (const std::string why = height_spread_blocker(m); !why.empty())
        throw InputError(where, key, why);
    fx.size_distribution = true;
    fx.height_spread = spread;
  } else if (name == "rolling_model") {
    if (!fx.rolling_friction)
      throw InputError(where, key, "a rolling model needs rolling_friction on");
    fx.rolling_model = dem::rolling_model_from_string(value, where, key);
  }
}

std::string model_fingerprint(const ParticleModel& m) {
  std::ostringstream s;
  s.precision(17);
  s << "basis " << to_string(m.mass_basis) << "\n";
  for (const auto& name : m.materials.names()) {
    const Material& mat = m.materials.get(name);
    s << "mat " << name << " " << mat.density << " " << mat.poisson_ratio << " "
      << mat.youngs_modulus << "\n";
    for (const auto& other : m.materials.names())
      if (m.materials.has_interaction(name, other)) {
        const Interaction& i = m.materials.interaction(name, other);
        s << "int " << name << " " << other << " " << i.restitution << " " << i.static_friction
          << " " << i.rolling_friction << "\n";
      }
  }
  for (const auto& t : m.types) {
    s << "type " << t.name << " " << t.shape.diameter << " " << t.shape.height << " "
      << t.shape.density << " " << t.mass_fraction << " " << t.paper_spheres.value_or(0) << " "
      << t.given_mass.value_or(0.0) << " ";
    // "@shape-density": since session 43 a template's union mass is at the shape file's
    // density (results cached before were made at the template's own).
    if (!t.clump_path.empty())
      s << read_file(t.clump_path).size() << ":"
        << std::hash<std::string>{}(read_file(t.clump_path)) << "@shape-density";
    // A mesh shape is what shape_resolution fills again: its bytes and scale are the model's.
    if (t.shape.kind == ShapeSpec::Kind::Mesh)
      s << " mesh " << t.shape.mesh_scale << " "
        << (path_exists(t.shape.mesh) ? std::hash<std::string>{}(read_file(t.shape.mesh))
                                      : std::size_t{0});
    s << "\n";
  }
  const ModelEffects& e = m.effects;
  auto partners = [&](const char* n, const std::optional<std::map<std::string, double>>& v) {
    s << n;
    if (v)
      for (const auto& [k, x] : *v) s << " " << k << "=" << x;
    else
      s << " absent";
    s << "\n";
  };
  partners("rolling_friction", e.rolling_friction);
  partners("wall_friction", e.wall_friction);
  partners("restitution", e.restitution);
  s << "particle_friction "
    << (e.particle_friction ? fmt::format("{:.17g}", *e.particle_friction) : "absent") << "\n";
  s << "cohesion " << (e.cohesion ? fmt::format("{:.17g}", *e.cohesion) : "absent") << "\n";
  s << "shape_resolution " << e.shape_resolution.value_or(0) << "\n";
  // One type without a height spread is one size whether the effect is listed or not.
  s << "size_distribution " << (e.size_distribution && (m.types.size() > 1 || e.height_spread > 0));
  if (e.size_distribution && e.height_spread > 0) s << fmt::format(" {:.17g}", e.height_spread);
  s << "\n";
  s << "rolling_model " << (e.rolling_model ? dem::to_string(*e.rolling_model) : "default") << " "
    << e.epsd_damping << "\n";
  return s.str();
}

}  // namespace clumpkit
