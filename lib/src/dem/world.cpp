// World creation (validation once), accessors, energies and the state hash.
#include <omp.h>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "clumpkit/core/error.hpp"
#include "clumpkit/dem/time_step.hpp"
#include "dem/world_impl.hpp"

namespace clumpkit::dem {

std::string fmt_g(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

namespace {

// Moves a template into its centroid-principal frame (as a safety net: templates from
// make_clump_template already are) and returns the shared type data.
TypeData make_type(const ClumpTypeSettings& t, const std::string& where, const std::string& f) {
  validate_spheres(t.clump.spheres, where + ": " + f + ".clump");
  const MassProperties& mp = t.clump.mass;
  if (!(mp.mass > 0.0) || !std::isfinite(mp.mass))
    throw InputError(where, f + ".clump.mass",
                     "the clump mass must be > 0 (got " + fmt_g(mp.mass) + " kg)");
  // Keep the template's own axes when it is already diagonal (the common case): no needless
  // rotation of a symmetric template.
  const PrincipalFrame frame = principal_frame(mp);
  const Eigen::Vector3d& moments = frame.moments;
  const Eigen::Matrix3d& axes = frame.axes;
  if (!(moments.minCoeff() > 0.0) || !moments.allFinite())
    throw InputError(where, f + ".clump.mass.inertia_tensor",
                     "principal moments of inertia must be > 0");
  TypeData d;
  d.mass = mp.mass;
  d.inertia = moments;
  d.inv_mass = 1.0 / d.mass;
  d.inv_inertia = d.inertia.cwiseInverse();
  d.volume = mp.volume;
  for (const Sphere& s : t.clump.spheres) {
    d.offsets.push_back(axes.transpose() * (s.center - mp.center_of_mass));
    d.radii.push_back(s.radius);
    d.bound_radius = std::max(d.bound_radius, d.offsets.back().norm() + s.radius);
  }
  return d;
}

}  // namespace

World::World(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;
World::~World() = default;

namespace {

// A factory's runtime from its settings, validated; k is its index (names the field in errors
// and seeds its random stream). `s` holds the clump types and the seed (World::create and
// World::add_factory).
FactoryRuntime make_factory(const World::Impl& w, const WorldSettings& s, const FactorySettings& fs,
                            size_t k) {
  const std::string& where = s.source;
  const std::string f = "factories[" + std::to_string(k) + "]";
  FactoryRuntime fr;
  fr.s = fs;
  if (fs.count.has_value() == fs.mass.has_value())
    throw InputError(where, f, "give exactly one of count and mass");
  if (fs.count && *fs.count < 0) throw InputError(where, f + ".count", "must be >= 0");
  if (fs.mass && !(*fs.mass >= 0.0 && std::isfinite(*fs.mass)))
    throw InputError(where, f + ".mass", "must be >= 0 kg");
  if (!(fs.rate >= 0.0) || !std::isfinite(fs.rate))
    throw InputError(where, f + ".rate", "must be >= 0");
  if (!(fs.interval >= 0.0)) throw InputError(where, f + ".interval", "must be >= 0 s");
  if (fs.attempts_per_clump < 1) throw InputError(where, f + ".attempts_per_clump", "must be >= 1");
  if (!(fs.end_below >= 0.0 && fs.end_below <= 1.0))
    throw InputError(where, f + ".end_below", "must be in [0, 1] (a fraction of one batch)");
  if (fs.mixture.empty()) throw InputError(where, f + ".mixture", "no clump types given");
  double total = 0.0;
  for (size_t e = 0; e < fs.mixture.size(); ++e) {
    const auto& me = fs.mixture[e];
    int t = -1;
    for (size_t u = 0; u < s.clump_types.size(); ++u)
      if (s.clump_types[u].name == me.clump_type) t = static_cast<int>(u);
    if (t < 0)
      throw InputError(where, f + ".mixture[" + std::to_string(e) + "].clump_type",
                       "unknown clump type '" + me.clump_type + "'");
    if (!(me.mass_fraction > 0.0) || !std::isfinite(me.mass_fraction))
      throw InputError(where, f + ".mixture[" + std::to_string(e) + "].mass_fraction",
                       "must be > 0");
    fr.types.push_back(t);
    fr.fractions.push_back(me.mass_fraction);
    total += me.mass_fraction;
  }
  for (double& x : fr.fractions) x /= total;
  fr.type_mass.assign(fr.types.size(), 0.0);
  // Region sanity: it must hold the largest clump of the mixture at all.
  double bound = 0.0;
  for (int t : fr.types) bound = std::max(bound, w.types[t].bound_radius);
  bool fits = true;
  if (const auto* b = std::get_if<BoxRegion>(&fs.region)) {
    if (!b->min.allFinite() || !b->max.allFinite() || !((b->max - b->min).minCoeff() > 0.0))
      throw InputError(where, f + ".region", "box min must be below max on every axis");
    fits = (b->max - b->min).minCoeff() >= 2.0 * bound;
    if (b->cuts.size() > kMaxRegionCuts)
      throw InputError(
          where, f + ".region.cuts",
          std::to_string(b->cuts.size()) + " planes; at most " + std::to_string(kMaxRegionCuts));
    for (size_t h = 0; h < b->cuts.size(); ++h)
      if (!b->cuts[h].point.allFinite() || !b->cuts[h].normal.allFinite() ||
          !(std::abs(b->cuts[h].normal.norm() - 1.0) < 1e-9))
        throw InputError(where, f + ".region.cuts[" + std::to_string(h) + "]",
                         "needs a finite point and a unit normal");
    if (fits && !b->cuts.empty()) {
      // Somewhere in the cut box a whole clump must fit: search a 32³ grid for such a centre.
      fits = false;
      const int n = 32;
      for (int i = 0; i < n && !fits; ++i)
        for (int j = 0; j < n && !fits; ++j)
          for (int l = 0; l < n && !fits; ++l) {
            const Eigen::Vector3d u((i + 0.5) / n, (j + 0.5) / n, (l + 0.5) / n);
            fits = region_contains(fs.region, b->min + (b->max - b->min).cwiseProduct(u), bound);
          }
    }
  } else {
    const auto& c = std::get<CylinderRegion>(fs.region);
    if (!(c.radius > 0.0) || !(c.height > 0.0) || !c.base_center.allFinite())
      throw InputError(where, f + ".region", "cylinder radius and height must be > 0");
    fits = c.radius >= bound && c.height >= 2.0 * bound;
  }
  if (!fits)
    throw InputError(where, f + ".region",
                     "the region (" + describe(fs.region) +
                         ") is smaller than a clump of the mixture (bounding radius " +
                         fmt_g(bound * 1e3) + " mm)");
  fr.rng.seed(s.seed + 0x9E3779B97F4A7C15ull * (k + 1));
  return fr;
}

}  // namespace

World World::create(WorldSettings s) {
  auto im = std::make_unique<Impl>();
  Impl& w = *im;
  const std::string& where = s.source;

  // Materials and the per-pair laws.
  for (const std::string& name : s.materials.names()) {
    const Material& m = s.materials.get(name);
    if (!(m.density > 0.0) || !std::isfinite(m.density))
      throw InputError(where, "materials." + name + ".density",
                       "density must be > 0 (got " + fmt_g(m.density) + " kg/m^3)");
    if (!(m.youngs_modulus > 0.0) || !std::isfinite(m.youngs_modulus))
      throw InputError(where, "materials." + name + ".youngs_modulus",
                       "stiffness must be > 0 (got " + fmt_g(m.youngs_modulus) + " Pa)");
    if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5))
      throw InputError(where, "materials." + name + ".poisson_ratio",
                       "Poisson ratio must lie in (-1, 0.5) (got " + fmt_g(m.poisson_ratio) + ")");
    w.material_index[name] = static_cast<int>(w.materials.size());
    w.materials.push_back(m);
  }
  const size_t nm = w.materials.size();
  for (size_t k = 0; k < s.pair_contacts.size(); ++k) {
    const auto& o = s.pair_contacts[k];
    const std::string f = "pair_contacts[" + std::to_string(k) + "]";
    s.materials.get(o.material_a, where, f + ".materials");
    s.materials.get(o.material_b, where, f + ".materials");
    o.law.validate(where, f);
  }
  // Which materials meet: particles with particles and walls; a missing interaction is only an
  // error for pairs that can touch.
  std::vector<char> particle_mat(nm, 0), wall_mat(nm, 0);

  // Clump types.
  if (s.clump_types.empty() && s.factories.empty() && s.walls.empty())
    throw InputError(where, "clump_types", "no clump types, walls or factories: nothing to run");
  for (size_t t = 0; t < s.clump_types.size(); ++t) {
    const std::string f = "clump_types[" + std::to_string(t) + "]";
    const auto& ct = s.clump_types[t];
    if (ct.name.empty()) throw InputError(where, f + ".name", "a clump type needs a name");
    for (size_t u = 0; u < t; ++u)
      if (s.clump_types[u].name == ct.name)
        throw InputError(where, f + ".name", "duplicate clump type '" + ct.name + "'");
    TypeData d = make_type(ct, where, f);
    s.materials.get(ct.material, where, f + ".material");
    d.material = w.material_index.at(ct.material);
    particle_mat[d.material] = 1;
    w.types.push_back(std::move(d));
  }

  // Walls.
  for (size_t k = 0; k < s.walls.size(); ++k) {
    const std::string f = "walls[" + std::to_string(k) + "]";
    const WallSettings& ws = s.walls[k];
    ws.mesh.validate(where, f + ".mesh");
    ws.motion.validate(where, f + ".motion");
    for (size_t u = 0; u < k; ++u)
      if (s.walls[u].name == ws.name)
        throw InputError(where, f + ".name", "duplicate wall name '" + ws.name + "'");
    s.materials.get(ws.material, where, f + ".material");
    WallData wd;
    wd.name = ws.name;
    wd.material = w.material_index.at(ws.material);
    wall_mat[wd.material] = 1;
    wd.ref_vertices = ws.mesh.vertices;
    wd.triangles = ws.mesh.triangles;
    for (const auto& t : wd.triangles) {
      const Eigen::Vector3d n = (wd.ref_vertices[t[1]] - wd.ref_vertices[t[0]])
                                    .cross(wd.ref_vertices[t[2]] - wd.ref_vertices[t[0]]);
      const double len = n.norm();
      wd.ref_normals.push_back(len > 0.0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero());
    }
    wd.motion = ws.motion;
    if (ws.torque_reference)
      wd.torque_reference0 = *ws.torque_reference;
    else if (ws.motion.rotation)
      wd.torque_reference0 = ws.motion.rotation->axis_point;
    w.walls.push_back(std::move(wd));
  }

  // Resolve every pair law that can be used; unknown interactions are input errors.
  w.laws.resize(nm * nm);
  const auto names = s.materials.names();
  for (size_t a = 0; a < nm; ++a)
    for (size_t b = 0; b < nm; ++b) {
      const bool used =
          (particle_mat[a] && (particle_mat[b] || wall_mat[b])) || (particle_mat[b] && wall_mat[a]);
      const Material& ma = w.materials[a];
      const Material& mb = w.materials[b];
      const PairContactOverride* over = nullptr;
      for (const auto& o : s.pair_contacts)
        if ((o.material_a == ma.name && o.material_b == mb.name) ||
            (o.material_a == mb.name && o.material_b == ma.name))
          over = &o;
      PairContact law;
      if (over) {
        law = over->law;
      } else if (s.materials.has_interaction(ma.name, mb.name)) {
        law = PairContact::from(s.materials.interaction(ma.name, mb.name), s.rolling_model);
        law.validate(where, "interactions(" + ma.name + ", " + mb.name + ")");
      } else if (used) {
        s.materials.interaction(ma.name, mb.name, where);  // throws the library's message
      }
      w.laws[a * nm + b] = resolve(ma, mb, law);
    }

  // Factories.
  for (size_t k = 0; k < s.factories.size(); ++k)
    w.factories.push_back(make_factory(w, s, s.factories[k], k));

  // Sizes, skin and the time step.
  w.r_min = std::numeric_limits<double>::infinity();
  w.r_max = 0.0;
  int smallest_type = -1;
  size_t smallest_sphere = 0;
  for (size_t t = 0; t < w.types.size(); ++t)
    for (size_t k = 0; k < w.types[t].radii.size(); ++k) {
      const double r = w.types[t].radii[k];
      if (r < w.r_min) {
        w.r_min = r;
        smallest_type = static_cast<int>(t);
        smallest_sphere = k;
      }
      w.r_max = std::max(w.r_max, r);
    }
  (void)smallest_sphere;
  if (!(s.skin >= 0.0)) throw InputError(where, "skin", "must be >= 0 m");
  if (!(s.rayleigh_fraction > 0.0)) throw InputError(where, "rayleigh_fraction", "must be > 0");
  if (!(s.time_step >= 0.0) || !std::isfinite(s.time_step))
    throw InputError(where, "time_step", "must be > 0 s (or 0 for the default)");
  if (!(s.max_impact_speed > 0.0)) throw InputError(where, "max_impact_speed", "must be > 0 m/s");
  if (!(s.max_speed > 0.0)) throw InputError(where, "max_speed", "must be > 0 m/s");
  if (s.check_interval < 1) throw InputError(where, "check_interval", "must be >= 1");
  if (!(s.pinch_release >= 0.0 && s.pinch_release < 0.5))
    throw InputError(where, "pinch_release",
                     "must be in [0, 0.5) (a fraction of a sphere radius; 0 = off)");
  if (!s.gravity.allFinite()) throw InputError(where, "gravity", "must be finite");
  if (!(s.implicit_damping >= 0.0 && s.implicit_damping <= 2.0))
    throw InputError(where, "implicit_damping",
                     "must be in [0, 2] (dashpot load x time step; 0 = off, 0.5 advised)");
  if (smallest_type >= 0) {
    const Material& m = w.materials[w.types[smallest_type].material];
    const double tr = rayleigh_time(w.r_min, m.density, m.shear_modulus(), m.poisson_ratio);
    w.dt = s.time_step > 0.0 ? s.time_step : s.rayleigh_fraction * tr;
    const double frac = w.dt / tr;
    if (frac > 0.4)
      w.warnings.push_back("time step " + fmt_g(w.dt) + " s is " + fmt_g(100.0 * frac) +
                           " % of the Rayleigh time " + fmt_g(tr) +
                           " s of the smallest sphere (above 40 %: expect instability)");
    // Two limits for every pair that can touch, at the largest expected impact speed
    // (time_step.hpp). Stiffness: the Hertz impact of the clump's equivalent mass for its
    // stiffest contact mode (normal springs; several spheres at once, rocking) spans 10 steps.
    // Damping: the contact damping is sized with the clumps' masses (as in LIGGGHTS) but acts
    // on contact points that can be far lighter (a pill turns easily about its axis), so its
    // rate Γ = c/m_eq (normal and tangential dashpots) must stay below 1/step: explicit damping
    // grows without bound above 2, and a jammed pill was seen to blow up at Γ dt = 1.98.
    constexpr double kStepsPerImpact = 10.0, kDampingLimit = 1.0;
    double tc_min = std::numeric_limits<double>::infinity(), gamma_max = 0.0, gamma_one = 0.0;
    std::string tc_what, gamma_what, one_what;
    // With implicit damping: the largest load its gate assigns to a single contact (step.cpp,
    // dashpot_load), at the impact's largest overlap. The default step keeps it below the gate,
    // so an isolated contact is integrated as before and keeps the restitution it was given.
    const bool implicit = s.implicit_damping > 0.0;
    // Per contact and clump: the normal and tangential loads of step.cpp's gate at the worst
    // lever arm (the clump's bounding radius), as a rate against the gates.
    auto consider_one = [&](const ResolvedContact& law, double r_star, double m_star,
                            const TypeData& ta, const TypeData* tb, const std::string& what) {
      if (!law.damping) return;
      const double d = hertz_max_overlap(law.e_star, r_star, m_star, s.max_impact_speed);
      const double cn = normal_dashpot_constant(law, r_star, m_star) * std::sqrt(std::sqrt(d));
      const double ct =
          law.friction ? tangential_dashpot(law, 8.0 * law.g_star * std::sqrt(r_star * d), m_star)
                       : 0.0;
      // Any direction: the lever arm reaches the bounding radius; along the normal only the
      // sphere centre's offset turns the clump (r × n = offset × n).
      auto mob = [](const TypeData& t, bool normal) {
        double arm = t.bound_radius;
        if (normal) {
          arm = 0.0;
          for (const auto& o : t.offsets) arm = std::max(arm, o.norm());
        }
        return t.inv_mass + arm * arm * t.inv_inertia.maxCoeff();
      };
      auto pair = [&](bool normal) {
        return tb ? 2.0 * std::max(mob(ta, normal), mob(*tb, normal)) : mob(ta, normal);
      };
      const double g = std::max(cn * pair(true), ct * pair(false) / kTangentialGate);
      if (g > gamma_one) gamma_one = g, one_what = what;
    };
    std::vector<SphereSet> shapes;
    std::vector<ClumpInertia> inertias;
    for (const auto& t : w.types) {
      shapes.push_back({t.offsets, t.radii});
      inertias.push_back({t.mass, t.inertia});
    }
    auto percent = [](double part, double whole) {
      return fmt_g(std::round(100.0 * part / whole));
    };
    // One pair of contact modes: normal-spring equivalent mass mn, dashpot equivalent mass mc.
    auto consider = [&](const ResolvedContact& law, double r_star, double m_star, double mn,
                        double mc, const std::string& what) {
      const double v = s.max_impact_speed;
      const double tc = hertz_contact_time(law.e_star, r_star, mn, v);
      if (tc < tc_min)
        tc_min = tc,
        tc_what = what + " (stiffest contact mode: " + percent(mn, m_star) + " % of the mass)";
      if (!law.damping || mc <= 0.0) return;
      const double stiffness =
          2.0 * law.e_star * std::sqrt(r_star * hertz_max_overlap(law.e_star, r_star, mn, v));
      const double gamma = contact_damping_factor() * law.beta * std::sqrt(stiffness * m_star) / mc;
      if (gamma > gamma_max)
        gamma_max = gamma,
        gamma_what = what + " (dashpots on " + percent(mc, m_star) + " % of the mass)";
    };
    for (size_t t = 0; t < w.types.size(); ++t) {
      for (size_t u = t; u < w.types.size(); ++u) {
        const auto& law = w.law(w.types[t].material, w.types[u].material);
        const double mst = w.types[t].mass * w.types[u].mass / (w.types[t].mass + w.types[u].mass);
        const double dash_t = std::sqrt(4.0 * law.g_star / law.e_star);  // c_t / c_n
        const double mn = clump_contact_mass(shapes[t], inertias[t], shapes[u], inertias[u], 0.0);
        // The dashpots' mode mass only sets the explicit scheme's limit (implicit damping off).
        const double mc =
            implicit ? 0.0
                     : clump_contact_mass(shapes[t], inertias[t], shapes[u], inertias[u], dash_t);
        for (double r : w.types[t].radii)
          for (double r2 : w.types[u].radii) {
            consider(law, r * r2 / (r + r2), mst, mn, mc, "clump-clump");
            consider_one(law, r * r2 / (r + r2), mst, w.types[t], &w.types[u],
                         "clump-clump contact");
          }
      }
      for (const auto& wd : w.walls) {
        const auto& law = w.law(w.types[t].material, wd.material);
        const double dash_t = std::sqrt(4.0 * law.g_star / law.e_star);
        const double mn = wall_contact_mass(shapes[t], inertias[t], 0.0);
        const double mc = implicit ? 0.0 : wall_contact_mass(shapes[t], inertias[t], dash_t);
        for (double r : w.types[t].radii) {
          consider(law, r, w.types[t].mass, mn, mc, "clump-wall '" + wd.name + "'");
          consider_one(law, r, w.types[t].mass, w.types[t], nullptr,
                       "clump-wall '" + wd.name + "' contact");
        }
      }
    }
    // The default time step honours all three limits: a fraction of the Rayleigh time, 10 steps
    // per impact, and the damping rate.
    // With implicit damping on (the default) the damping of jammed clumps cannot overshoot at
    // any step, so only a single contact's rate bounds the default step (docs/dem.md, implicit
    // damping); without it, the stiffest contact mode's.
    if (s.time_step <= 0.0) {
      const double was = w.dt;
      if (tc_min / w.dt < kStepsPerImpact) w.dt = tc_min / kStepsPerImpact;
      if (implicit && gamma_one * w.dt > s.implicit_damping) w.dt = s.implicit_damping / gamma_one;
      if (!implicit && gamma_max * w.dt > kDampingLimit) w.dt = kDampingLimit / gamma_max;
      if (w.dt < was) {
        std::string why = "a " + tc_what + " impact at " + fmt_g(s.max_impact_speed) +
                          " m/s lasts " + fmt_g(tc_min) + " s, which needs 10 steps";
        if (implicit && w.dt * gamma_one >= s.implicit_damping * (1.0 - 1e-12))
          why = "the dashpots of a single " + one_what + " damp at up to " + fmt_g(gamma_one) +
                " /s, which needs steps of at most " + fmt_g(s.implicit_damping) + "/rate";
        if (!implicit && w.dt * gamma_max >= kDampingLimit * (1.0 - 1e-12))
          why = "the contact damping of a " + gamma_what + " acts at a rate of " +
                fmt_g(gamma_max) + " /s, which needs steps of at most 1/rate";
        w.warnings.push_back("time step " + fmt_g(w.dt) + " s instead of " +
                             fmt_g(s.rayleigh_fraction) + " x the Rayleigh time (" + fmt_g(was) +
                             " s): " + why);
      }
    }
    if (implicit && gamma_one * w.dt > s.implicit_damping)
      w.warnings.push_back("the dashpots of a single " + one_what + " damp at up to " +
                           fmt_g(gamma_one) + " /s: at the time step " + fmt_g(w.dt) +
                           " s such contacts are damped implicitly (backward Euler), which "
                           "dissipates differently from the explicit scheme their restitution "
                           "is calibrated with (a step of " +
                           fmt_g(s.implicit_damping / gamma_one) + " s would not)");
    const double per = tc_min / w.dt;
    if (per < 4.0)
      throw InputError(where, "time_step",
                       "time step " + fmt_g(w.dt) + " s is above the stability limit: a " +
                           tc_what + " impact at " + fmt_g(s.max_impact_speed) + " m/s lasts " +
                           fmt_g(tc_min) + " s, only " + fmt_g(per) +
                           " steps (at least 4 needed, 10 advised)");
    if (!implicit && gamma_max * w.dt >= 2.0)
      throw InputError(where, "time_step",
                       "time step " + fmt_g(w.dt) + " s is above the stability limit of the " +
                           "contact damping: a " + gamma_what + " damps at a rate of " +
                           fmt_g(gamma_max) + " /s, and explicit damping grows without bound " +
                           "above 2/rate = " + fmt_g(2.0 / gamma_max) + " s (1/rate advised)");
    if (per < kStepsPerImpact)
      w.warnings.push_back("a " + tc_what + " impact at " + fmt_g(s.max_impact_speed) +
                           " m/s lasts only " + fmt_g(per) + " steps (10 or more advised)");
    if (!implicit && gamma_max * w.dt > kDampingLimit)
      w.warnings.push_back("the contact damping of a " + gamma_what + " acts at a rate of " +
                           fmt_g(gamma_max) + " /s: the time step " + fmt_g(w.dt) +
                           " s is above 1/rate (a jammed pill was seen to blow up at 1.98/rate)");
    w.skin = s.skin > 0.0 ? s.skin : 0.3 * w.r_min;
    w.cell = 2.0 * w.r_max + w.skin;
  } else {
    w.dt = s.time_step > 0.0 ? s.time_step : 1e-5;
    w.skin = s.skin > 0.0 ? s.skin : 1e-3;
    w.cell = w.skin;
    w.r_min = w.r_max = 0.0;
  }
  w.max_threads = omp_get_max_threads();
  w.threads = s.threads > 0 ? s.threads : 1;
  w.wall_cand_start.assign(1, 0);
  w.settings = std::move(s);
  w.move_walls();
  for (auto& wd : w.walls) wd.vertices_build = wd.vertices;
  w.fingerprint = w.compute_fingerprint();
  // At-once factories due at t = 0 run now, so a region too small is reported at creation.
  w.run_factories();
  return World(std::move(im));
}

int World::Impl::add_clump(int type, const Eigen::Vector3d& x, const Eigen::Quaterniond& q,
                           const Eigen::Vector3d& v, const Eigen::Vector3d& w_world) {
  const TypeData& t = types[type];
  const int c = static_cast<int>(c_x.size());
  const Eigen::Quaterniond qn = q.normalized();
  c_type.push_back(type);
  c_first.push_back(static_cast<int>(s_r.size()));
  c_x.push_back(x);
  c_v.push_back(v);
  c_q.push_back(qn);
  c_R.push_back(qn.toRotationMatrix());
  c_wb.push_back(c_R.back().transpose() * w_world);
  c_f.push_back(Eigen::Vector3d::Zero());
  c_t.push_back(Eigen::Vector3d::Zero());
  c_mroll.push_back(0.0);
  for (size_t k = 0; k < t.radii.size(); ++k) {
    s_clump.push_back(c);
    s_r.push_back(t.radii[k]);
    s_off.push_back(t.offsets[k]);
    const Eigen::Vector3d p = sphere_position(x, c_R.back(), t.offsets[k]);
    s_pos.push_back(p);
    s_pos_build.push_back(p);
    wall_slots.emplace_back();
    wall_held.push_back(0);
    wall_row.push_back(-1);  // a row in wall_contacts once wall_active is refreshed
    wall_contact_n.push_back(0);
    wall_cand_start.push_back(wall_cand_start.back());
  }
  need_rebuild = true;
  wall_active_dirty = true;
  return c;
}

int World::add_clump(int type, const Eigen::Vector3d& x, const Eigen::Quaterniond& q,
                     const Eigen::Vector3d& v, const Eigen::Vector3d& w) {
  if (type < 0 || type >= clump_type_count())
    throw InputError(impl_->settings.source, "clump type", "index out of range");
  if (!x.allFinite() || !v.allFinite() || !w.allFinite() || !q.coeffs().allFinite())
    throw InputError(impl_->settings.source, "clump state", "non-finite value");
  const int c = impl_->add_clump(type, x, q, v, w);
  // Energy brought in by hand counts as a source in the blow-up check's balance.
  const TypeData& t = impl_->types[type];
  impl_->inserted_energy += 0.5 * t.mass * v.squaredNorm() +
                            0.5 * impl_->c_wb[c].dot(t.inertia.cwiseProduct(impl_->c_wb[c])) -
                            t.mass * impl_->settings.gravity.dot(x);
  return c;
}

void World::set_wall_motion(int w, const WallMotion& motion) {
  Impl& im = *impl_;
  const std::string& where = im.settings.source;
  if (w < 0 || w >= static_cast<int>(im.walls.size()))
    throw InputError(where, "set_wall_motion", "wall index out of range");
  motion.validate(where, "walls[" + std::to_string(w) + "].motion");
  im.walls[w].motion = motion;
  im.settings.walls[w].motion = motion;
  // The pose at the current time; a jump (if any) triggers a neighbour rebuild next step.
  im.move_walls();
}

void World::add_factory(const FactorySettings& f) {
  Impl& im = *impl_;
  // Batches are scheduled from the start time: one in the past would be caught up at once.
  if (!(f.start_time >= im.time))
    throw InputError(im.settings.source,
                     "factories[" + std::to_string(im.factories.size()) + "].start_time",
                     "a factory added at t = " + fmt_g(im.time) +
                         " s must start then or later (got " + fmt_g(f.start_time) + " s)");
  im.factories.push_back(make_factory(im, im.settings, f, im.factories.size()));
  im.settings.factories.push_back(f);
  // A World created with this factory in its settings has the same fingerprint, so the
  // checkpoints taken from now on load into it.
  im.fingerprint = im.compute_fingerprint();
}

int World::remove_clumps(const std::function<bool(int)>& remove) {
  Impl& w = *impl_;
  const int nc = static_cast<int>(w.c_x.size());
  std::vector<int> clump_map(nc, -1);
  int kept = 0;
  for (int c = 0; c < nc; ++c)
    if (!remove(c)) clump_map[c] = kept++;
  if (kept == nc) return 0;
  for (int c = 0; c < nc; ++c)
    if (clump_map[c] < 0) {
      const TypeData& t = w.types[w.c_type[c]];
      // The energy they carried leaves the balance of the blow-up check with them.
      w.check_energy -= 0.5 * t.mass * w.c_v[c].squaredNorm() +
                        0.5 * w.c_wb[c].dot(t.inertia.cwiseProduct(w.c_wb[c])) -
                        t.mass * w.settings.gravity.dot(w.c_x[c]);
    }
  auto compact = [&](auto& v, const std::vector<int>& map) {
    size_t o = 0;
    for (size_t k = 0; k < map.size(); ++k)
      if (map[k] >= 0) v[o++] = v[k];
    v.resize(o);
  };
  const int ns = static_cast<int>(w.s_r.size());
  std::vector<int> sphere_map(ns, -1);
  int ks = 0;
  for (int s = 0; s < ns; ++s)
    if (clump_map[w.s_clump[s]] >= 0) sphere_map[s] = ks++;
  compact(w.c_type, clump_map);
  compact(w.c_x, clump_map);
  compact(w.c_v, clump_map);
  compact(w.c_wb, clump_map);
  compact(w.c_q, clump_map);
  compact(w.c_R, clump_map);
  compact(w.c_f, clump_map);
  compact(w.c_t, clump_map);
  compact(w.c_mroll, clump_map);
  for (int s = 0; s < ns; ++s) w.s_clump[s] = clump_map[w.s_clump[s]];
  compact(w.s_clump, sphere_map);
  compact(w.s_r, sphere_map);
  compact(w.s_off, sphere_map);
  compact(w.s_pos, sphere_map);
  compact(w.s_pos_build, sphere_map);
  compact(w.wall_slots, sphere_map);
  w.recount_wall_held();
  w.c_first.assign(kept, 0);
  for (int s = ks - 1; s >= 0; --s) w.c_first[w.s_clump[s]] = s;
  // Pair lists stay sorted under the monotone renumbering.
  size_t o = 0;
  for (size_t k = 0; k < w.pairs.size(); ++k) {
    const int i = sphere_map[w.pairs[k].i], j = sphere_map[w.pairs[k].j];
    if (i < 0 || j < 0) continue;
    w.pairs[o] = {i, j};
    w.pair_hist[o] = w.pair_hist[k];
    ++o;
  }
  w.pairs.resize(o);
  w.pair_hist.resize(o);
  w.pair_live.clear();  // rebuilt from the histories at the next detection
  // Contacts of the last evaluation are dropped; wall candidates are rebuilt next step.
  w.pair_contacts.clear();
  w.pair_contact_clumps.clear();
  w.wall_contacts.clear();
  w.wall_row.assign(ks, -1);
  w.wall_contact_n.assign(ks, 0);
  w.wall_cand.clear();
  w.wall_cand_start.assign(ks + 1, 0);
  w.need_rebuild = true;
  w.wall_active_dirty = true;
  return nc - kept;
}

double World::Impl::kinetic_energy() const {
  double e = 0.0;
  for (size_t c = 0; c < c_x.size(); ++c) {
    const TypeData& t = types[c_type[c]];
    e += 0.5 * t.mass * c_v[c].squaredNorm() + 0.5 * c_wb[c].dot(t.inertia.cwiseProduct(c_wb[c]));
  }
  return e;
}

double World::Impl::potential_energy() const {
  double e = 0.0;
  for (size_t c = 0; c < c_x.size(); ++c) e -= types[c_type[c]].mass * settings.gravity.dot(c_x[c]);
  return e;
}

std::uint64_t World::Impl::compute_fingerprint() const {
  Hasher h;
  h.value(dt);
  h.value(materials.size());
  for (const auto& t : types) {
    h.value(t.mass);
    h.value(t.material);
    h.vec(t.radii);
    h.vec(t.offsets);
  }
  for (const auto& wd : walls) {
    h.value(wd.material);
    h.vec(wd.ref_vertices);
    h.vec(wd.triangles);
  }
  h.value(factories.size());
  h.value(settings.seed);
  h.value(settings.implicit_damping);
  return h.h;
}

// Accessors.
double World::time() const {
  return impl_->time;
}
long World::step_count() const {
  return impl_->steps;
}
double World::dt() const {
  return impl_->dt;
}
const std::vector<std::string>& World::warnings() const {
  return impl_->warnings;
}
int World::pinched_count() const {
  return impl_->pinched_count;
}
double World::pinched_mass() const {
  return impl_->pinched_mass;
}
const Profile& World::profile() const {
  return impl_->profile;
}
Profile& World::profile() {
  return impl_->profile;
}
const WorldSettings& World::settings() const {
  return impl_->settings;
}
int World::clump_type_count() const {
  return static_cast<int>(impl_->types.size());
}
int World::clump_type_index(const std::string& name) const {
  const auto& ct = impl_->settings.clump_types;
  for (size_t t = 0; t < ct.size(); ++t)
    if (ct[t].name == name) return static_cast<int>(t);
  throw InputError(impl_->settings.source, "clump_type", "unknown clump type '" + name + "'");
}
const ClumpTypeSettings& World::clump_type(int t) const {
  return impl_->settings.clump_types[t];
}
double World::clump_type_mass(int t) const {
  return impl_->types[t].mass;
}
Eigen::Vector3d World::clump_type_inertia(int t) const {
  return impl_->types[t].inertia;
}
int World::clump_count() const {
  return static_cast<int>(impl_->c_x.size());
}
long World::sphere_count() const {
  return static_cast<long>(impl_->s_r.size());
}
int World::clump_type_of(int c) const {
  return impl_->c_type[c];
}
double World::clump_mass(int c) const {
  return impl_->types[impl_->c_type[c]].mass;
}
const std::vector<Eigen::Vector3d>& World::positions() const {
  return impl_->c_x;
}
const std::vector<Eigen::Quaterniond>& World::orientations() const {
  return impl_->c_q;
}
const std::vector<Eigen::Vector3d>& World::velocities() const {
  return impl_->c_v;
}
const std::vector<Eigen::Vector3d>& World::omegas_body() const {
  return impl_->c_wb;
}
Eigen::Vector3d World::omega_world(int c) const {
  return impl_->c_R[c] * impl_->c_wb[c];
}
void World::set_velocity(int c, const Eigen::Vector3d& v) {
  const double m = impl_->types[impl_->c_type[c]].mass;
  impl_->inserted_energy += 0.5 * m * (v.squaredNorm() - impl_->c_v[c].squaredNorm());
  impl_->c_v[c] = v;
}
void World::set_omega_world(int c, const Eigen::Vector3d& w) {
  const Eigen::Vector3d& inertia = impl_->types[impl_->c_type[c]].inertia;
  const Eigen::Vector3d wb = impl_->c_R[c].transpose() * w;
  impl_->inserted_energy += 0.5 * (wb.dot(inertia.cwiseProduct(wb)) -
                                   impl_->c_wb[c].dot(inertia.cwiseProduct(impl_->c_wb[c])));
  impl_->c_wb[c] = wb;
}
const std::vector<Eigen::Vector3d>& World::contact_forces() const {
  return impl_->c_f;
}
const std::vector<Eigen::Vector3d>& World::contact_torques() const {
  return impl_->c_t;
}
const std::vector<Eigen::Vector3d>& World::sphere_positions() const {
  return impl_->s_pos;
}
const std::vector<double>& World::sphere_radii() const {
  return impl_->s_r;
}
const std::vector<int>& World::sphere_clumps() const {
  return impl_->s_clump;
}
int World::wall_count() const {
  return static_cast<int>(impl_->walls.size());
}
int World::wall_index(const std::string& name) const {
  for (size_t k = 0; k < impl_->walls.size(); ++k)
    if (impl_->walls[k].name == name) return static_cast<int>(k);
  throw InputError(impl_->settings.source, "wall", "unknown wall '" + name + "'");
}
const WallSettings& World::wall_settings(int w) const {
  return impl_->settings.walls[w];
}
const WallState& World::wall(int w) const {
  return impl_->walls[w].state;
}
const std::vector<Eigen::Vector3d>& World::wall_vertices(int w) const {
  return impl_->walls[w].vertices;
}
int World::factory_count() const {
  return static_cast<int>(impl_->factories.size());
}
const FactoryStatus& World::factory_status(int f) const {
  return impl_->factories[f].status;
}
bool World::factories_done() const {
  for (const auto& f : impl_->factories)
    if (!f.status.done) return false;
  return true;
}
double World::kinetic_energy() const {
  return impl_->kinetic_energy();
}
double World::potential_energy() const {
  return impl_->potential_energy();
}
double World::elastic_energy() const {
  return impl_->elastic;
}
double World::total_mass() const {
  double m = 0.0;
  for (int t : impl_->c_type) m += impl_->types[t].mass;
  return m;
}
int World::contact_count() const {
  int n = 0;
  for (const auto& pc : impl_->pair_contacts) n += pc.closing ? 0 : 1;
  for (size_t s = 0; s < impl_->wall_contact_n.size(); ++s)
    for (int k = 0; k < impl_->wall_contact_n[s]; ++k)
      n += impl_->wall_contacts_of(static_cast<int>(s))[k].closing ? 0 : 1;
  return n;
}

std::vector<ContactInfo> World::contacts() const {
  const Impl& w = *impl_;
  std::vector<ContactInfo> out;
  for (const auto& pc : w.pair_contacts) {
    if (pc.closing) continue;  // not a contact any more, only its last damping impulse
    const PairEntry& p = w.pairs[pc.pair];
    out.push_back(
        {w.s_clump[p.i], w.s_clump[p.j], -1, pc.point, pc.normal, pc.overlap, pc.out.force});
  }
  for (size_t s = 0; s < w.wall_contact_n.size(); ++s)
    for (int k = 0; k < w.wall_contact_n[s]; ++k) {
      const auto& wc = w.wall_contacts_of(static_cast<int>(s))[k];
      if (wc.closing) continue;
      out.push_back({w.s_clump[s], -1, wc.wall, wc.point, wc.normal, wc.overlap, wc.out.force});
    }
  return out;
}

const ResolvedContact& World::resolved_contact(const std::string& a, const std::string& b) const {
  const auto& idx = impl_->material_index;
  auto ia = idx.find(a), ib = idx.find(b);
  if (ia == idx.end() || ib == idx.end())
    throw InputError(impl_->settings.source, "material",
                     "unknown material '" + (ia == idx.end() ? a : b) + "'");
  return impl_->law(ia->second, ib->second);
}

std::uint64_t World::state_hash() const {
  const Impl& w = *impl_;
  Hasher h;
  h.value(w.time);
  h.value(w.steps);
  h.vec(w.c_type);
  h.vec(w.c_x);
  h.vec(w.c_v);
  h.vec(w.c_wb);
  for (const auto& q : w.c_q) h.value(q.coeffs().eval());
  h.vec(w.c_f);
  h.vec(w.c_t);
  h.vec(w.c_mroll);
  for (size_t k = 0; k < w.pairs.size(); ++k)
    if (!history_empty(w.pair_hist[k])) {
      h.value(w.pairs[k]);
      h.value(w.pair_hist[k]);
    }
  for (const auto& slots : w.wall_slots)
    for (const auto& sl : slots) {
      h.value(sl.wall);
      if (sl.wall >= 0) {
        h.value(sl.normal);
        h.value(sl.history);
      }
    }
  for (const auto& wd : w.walls) {
    h.value(wd.state.force);
    h.value(wd.state.torque);
  }
  for (const auto& f : w.factories) {
    h.value(f.status.inserted);
    h.value(f.status.inserted_mass);
  }
  return h.h;
}

}  // namespace clumpkit::dem
