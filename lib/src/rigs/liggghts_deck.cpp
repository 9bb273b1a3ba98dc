// A rig as a LIGGGHTS 3.8 deck: the scene from the engine settings, the procedure as script
// loops, the run under MPI and its dumps read back (liggghts_deck.hpp).
#include "liggghts_deck.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include "clumpkit/core/error.hpp"
#include "clumpkit/export/exporter.hpp"

namespace clumpkit::rigs::detail {

using Eigen::Vector3d;

namespace {

std::string g(double x) {
  return fmt::format("{:.10g}", x);
}

std::string ascii_stl(const dem::TriangleMesh& m, const std::string& name) {
  std::string s = "solid " + name + "\n";
  for (const auto& t : m.triangles) {
    const Vector3d &a = m.vertices[t[0]], &b = m.vertices[t[1]], &c = m.vertices[t[2]];
    const Vector3d n = (b - a).cross(c - a).normalized();
    s += fmt::format(" facet normal {} {} {}\n  outer loop\n", g(n.x()), g(n.y()), g(n.z()));
    for (const Vector3d* v : {&a, &b, &c})
      s += fmt::format("   vertex {} {} {}\n", g(v->x()), g(v->y()), g(v->z()));
    s += "  endloop\n endfacet\n";
  }
  return s + "endsolid " + name + "\n";
}

// LIGGGHTS fix and file names: letters, digits and underscores.
std::string ident(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

bool is_prime(std::uint64_t n) {
  if (n < 2) return false;
  for (std::uint64_t d = 2; d * d <= n; ++d)
    if (n % d == 0) return false;
  return true;
}

std::string region_command(const std::string& id, const dem::Region& r) {
  if (const auto* c = std::get_if<dem::CylinderRegion>(&r))
    return fmt::format("region {} cylinder z {} {} {} {} {} units box", id, g(c->base_center.x()),
                       g(c->base_center.y()), g(c->radius), g(c->base_center.z()),
                       g(c->base_center.z() + c->height));
  const auto& b = std::get<dem::BoxRegion>(r);
  const std::string box = b.cuts.empty() ? id : id + "_box";
  std::string out =
      fmt::format("region {} block {} {} {} {} {} {} units box", box, g(b.min.x()), g(b.max.x()),
                  g(b.min.y()), g(b.max.y()), g(b.min.z()), g(b.max.z()));
  if (b.cuts.empty()) return out;
  // A box cut by planes: the intersection of the block with each plane's inner side.
  std::string parts = box;
  for (size_t k = 0; k < b.cuts.size(); ++k) {
    const dem::HalfSpace& h = b.cuts[k];
    out += fmt::format("\nregion {}_cut{} plane {} {} {} {} {} {} side in units box", id, k,
                       g(h.point.x()), g(h.point.y()), g(h.point.z()), g(h.normal.x()),
                       g(h.normal.y()), g(h.normal.z()));
    parts += fmt::format(" {}_cut{}", id, k);
  }
  return out + fmt::format("\nregion {} intersect {} {}", id, b.cuts.size() + 1, parts);
}

double region_height(const dem::Region& r) {
  if (const auto* c = std::get_if<dem::CylinderRegion>(&r)) return c->height;
  const auto& b = std::get<dem::BoxRegion>(r);
  return b.max.z() - b.min.z();
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string which(const std::string& exe) {
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "");
  std::string dir;
  while (std::getline(ss, dir, ':')) {
    const std::string p = (dir.empty() ? "." : dir) + "/" + exe;
    if (::access(p.c_str(), X_OK) == 0) return p;
  }
  return "";
}

}  // namespace

LiggghtsDeck::LiggghtsDeck(const dem::WorldSettings& ws, const Eigen::AlignedBox3d& domain,
                           double floor_z, double dt, std::uint64_t seed, const std::string& title)
    : dt_(dt), prime_(10007 + 7919 * (seed % 100000)) {
  // Atom types: one per material in use, the clumps' first.
  std::vector<std::string> mats;
  auto type_of = [&](const std::string& m) {
    for (size_t k = 0; k < mats.size(); ++k)
      if (mats[k] == m) return int(k) + 1;
    mats.push_back(m);
    return int(mats.size());
  };
  for (const auto& t : ws.clump_types) type_of(t.material);
  for (const auto& w : ws.walls) type_of(w.material);

  // The law of every pair of types: the settings' override, else the library's interaction.
  const int n = int(mats.size());
  std::vector<dem::PairContact> laws(size_t(n * n));
  std::map<dem::RollingModel, int> rolling_models;
  bool cohesion = false;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      dem::PairContact law;
      bool found = false;
      for (const auto& o : ws.pair_contacts)
        if ((o.material_a == mats[i] && o.material_b == mats[j]) ||
            (o.material_a == mats[j] && o.material_b == mats[i]))
          law = o.law, found = true;
      if (!found && ws.materials.has_interaction(mats[i], mats[j]))
        law = dem::PairContact::from(ws.materials.interaction(mats[i], mats[j]), ws.rolling_model);
      if (law.rolling && law.rolling->coefficient > 0) ++rolling_models[law.rolling->model];
      cohesion = cohesion || (law.cohesion && law.cohesion->energy_density > 0);
      laws[size_t(i * n + j)] = law;
    }
  std::string rolling;
  if (!rolling_models.empty()) {
    const dem::RollingModel m = rolling_models.rbegin()->first;
    if (rolling_models.size() > 1)
      notes_.push_back("the model mixes rolling-friction models; LIGGGHTS takes one for all pairs");
    if (m == dem::RollingModel::kEpsd) {
      rolling = " rolling_friction epsd2";
      notes_.push_back(
          "rolling friction: LIGGGHTS's epsd2 (elastic-plastic spring, no rolling dashpot) for "
          "clumpkit's EPSD type C");
    } else {
      rolling = " rolling_friction cdt";
      if (m != dem::RollingModel::kCdt)
        notes_.push_back(fmt::format(
            "rolling friction: LIGGGHTS has no '{}' model (paper eq. 2); its CDT model is used "
            "(torque on the relative rotation, R* instead of the sub-sphere radius)",
            dem::to_string(m)));
    }
  }
  notes_.push_back(
      "no implicit damping in LIGGGHTS: the time step is the bundled runner's explicit one "
      "(implicit_damping off)");

  auto matrix = [&](auto value) {
    std::vector<std::string> v;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) v.push_back(g(value(laws[size_t(i * n + j)])));
    return fmt::format("{} {}", n, fmt::join(v, " "));
  };
  const Vector3d lo = domain.min(), hi = domain.max();
  const std::string model = "model hertz tangential history" + rolling +
                            (cohesion ? std::string(" cohesion sjkr") : std::string());
  lines_ = {
      "# " + title,
      "# Generated by clumpkit (SI units). Types: " +
          [&] {
            std::string s;
            for (int k = 0; k < n; ++k)
              s += fmt::format("{}{} = {}", k ? ", " : "", k + 1, mats[k]);
            return s;
          }(),
      "atom_style sphere",
      "atom_modify map array",
      "boundary f f f",
      "newton off",
      "communicate single vel yes",
      "units si",
      "hard_particles yes",
      fmt::format("region domain block {} {} {} {} {} {} units box", g(lo.x()), g(hi.x()),
                  g(lo.y()), g(hi.y()), g(lo.z()), g(hi.z())),
      fmt::format("create_box {} domain", n),
      fmt::format("neighbor {} bin", g(ws.skin > 0 ? ws.skin : 0.001)),
      "neigh_modify delay 0",
  };
  std::string e = "fix m1 all property/global youngsModulus peratomtype",
              nu = "fix m2 all property/global poissonsRatio peratomtype";
  for (const auto& m : mats) {
    e += " " + g(ws.materials.get(m).youngs_modulus);
    nu += " " + g(ws.materials.get(m).poisson_ratio);
  }
  line(e);
  line(nu);
  line("fix m3 all property/global coefficientRestitution peratomtypepair " +
       matrix([](const dem::PairContact& l) { return l.restitution.value_or(1.0); }));
  line("fix m4 all property/global coefficientFriction peratomtypepair " +
       matrix([](const dem::PairContact& l) { return l.static_friction.value_or(0.0); }));
  if (!rolling.empty())
    line(
        "fix m5 all property/global coefficientRollingFriction peratomtypepair " +
        matrix([](const dem::PairContact& l) { return l.rolling ? l.rolling->coefficient : 0.0; }));
  if (cohesion)
    line("fix m6 all property/global cohesionEnergyDensity peratomtypepair " +
         matrix([](const dem::PairContact& l) {
           return l.cohesion ? l.cohesion->energy_density : 0.0;
         }));
  line("pair_style gran " + model);
  line("pair_coeff * *");
  line("timestep " + g(dt));
  const double gn = ws.gravity.norm();
  const Vector3d gd = gn > 0 ? Vector3d(ws.gravity / gn) : Vector3d(0, 0, -1);
  line(fmt::format("fix gravity all gravity {} vector {} {} {}", g(gn), g(gd.x()), g(gd.y()),
                   g(gd.z())));

  // Walls, at rest: a mesh file and a fix each, one wall/gran fix over all of them.
  std::string meshes;
  for (const auto& w : ws.walls) {
    const std::string id = ident(w.name);
    files_.push_back({id + ".stl", ascii_stl(w.mesh, id)});
    line(fmt::format("fix {} all mesh/surface file {}.stl type {}", id, id, type_of(w.material)));
    meshes += " " + id;
  }
  if (!ws.walls.empty())
    line(fmt::format("fix walls all wall/gran {} mesh n_meshes {} meshes{}", model, ws.walls.size(),
                     meshes));

  // Clump templates: the exporter's snippet (union mass and inertia tensor) and spheres file.
  for (size_t k = 0; k < ws.clump_types.size(); ++k) {
    const auto& t = ws.clump_types[k];
    ExportSettings es;
    es.base_name = "type_" + ident(t.name);
    es.template_type = int(k) + 1;
    es.atom_type = type_of(t.material);
    for (ExportFile f : render_export(in_principal_frame(t.clump), "liggghts", es)) {
      // LIGGGHTS wants every seed of an insertion (templates, distribution, insertion) different.
      const std::string key = "particletemplate/multisphere ";
      if (const size_t at = f.content.find(key); at != std::string::npos) {
        const size_t from = at + key.size(), to = f.content.find(' ', from);
        f.content.replace(from, to - from, std::to_string(next_prime()));
      }
      files_.push_back({f.name, f.content});
      if (f.name.ends_with(".liggghts")) line("include " + f.name);
    }
    template_ids_.push_back("pts_" + ident(es.base_name));
    type_names_.push_back(t.name);
    type_volumes_.push_back(t.clump.mass.volume);
  }
  line("fix integrate all multisphere allow_group_and_set yes");
  // The settle criterion's speed: RMS over the spheres (a clump's spheres move with it) above
  // the rig's floor (below it a pill has left the rig: the bundled runner removes it).
  line(fmt::format("variable in atom z>{}", g(floor_z)));
  line("variable v2 atom (vx*vx+vy*vy+vz*vz)*v_in");
  line("compute v2sum all reduce sum v_v2");
  line("compute insum all reduce sum v_in");
  line("variable rms equal sqrt(c_v2sum/(c_insum+1e-30))");
  line("variable now equal time");
  line("thermo_style custom step time atoms c_insum c_v2sum");
  line(fmt::format("thermo {}", std::max(1L, steps(0.01))));
  line("thermo_modify lost ignore norm no");
}

long LiggghtsDeck::steps(double seconds) const {
  return std::max(0L, long(std::ceil(seconds / dt_ - 1e-9)));
}

std::uint64_t LiggghtsDeck::next_prime() {
  do ++prime_;
  while (!is_prime(prime_));
  return prime_;
}

double LiggghtsDeck::insert(const dem::FactorySettings& f, const std::string& mass_variable) {
  const int k = ++factories_;
  std::string dist;
  double fractions = 0;
  for (const auto& e : f.mixture) fractions += e.mass_fraction;
  int entries = 0;
  for (const auto& e : f.mixture)
    for (size_t t = 0; t < type_names_.size(); ++t)
      if (type_names_[t] == e.clump_type) {
        dist += fmt::format(" {} {}", template_ids_[t], g(e.mass_fraction / fractions));
        ++entries;
      }
  if (entries == 0)
    throw InputError("LIGGGHTS deck", "factory " + f.name, "its mixture names no clump type");
  line(fmt::format("fix pdd{} all particledistribution/discrete {} {}{}", k, next_prime(), entries,
                   dist));
  line(region_command(fmt::format("pour{}", k), f.region));
  const std::string common = fmt::format(
      "maxattempt {} {} overlapcheck yes all_in {} orientation {} vel constant {} {} {}",
      f.attempts_per_clump, "{every}", f.whole_in_region ? "yes" : "no",
      f.random_orientation ? "random" : "template", g(f.velocity.x()), g(f.velocity.y()),
      g(f.velocity.z()));
  const std::string amount = !mass_variable.empty() ? "mass ${" + mass_variable + "}"
                             : f.mass               ? fmt::format("mass {}", g(*f.mass))
                                                    : fmt::format("nparticles {}", *f.count);
  if (f.rate <= 0.0) {
    if (!mass_variable.empty())
      throw InputError("LIGGGHTS deck", "factory " + f.name, "a top-up needs a rate");
    const std::string target = f.mass ? fmt::format("mass_in_region {}", g(*f.mass))
                                      : fmt::format("particles_in_region {}", *f.count);
    std::string c = common;
    c.replace(c.find("{every}"), 7, "insert_every once");
    line(
        fmt::format("fix ins{} all insert/pack seed {} distributiontemplate pdd{} {} {} region "
                    "pour{}",
                    k, next_prime(), k, c, target, k));
    last_interval_ = 0;
    return 0.0;
  }
  const double interval =
      f.interval > 0 ? f.interval : std::sqrt(2.0 * region_height(f.region) / 9.81);
  std::string c = common;
  c.replace(c.find("{every}"), 7, fmt::format("insert_every {}", std::max(1L, steps(interval))));
  line(
      fmt::format("fix ins{} all insert/rate/region seed {} distributiontemplate pdd{} {} {} {} "
                  "region pour{}",
                  k, next_prime(), k, amount,
                  f.mass ? "massrate " + g(f.rate) : "particlerate " + g(f.rate), c, k));
  last_interval_ = std::max(1L, steps(interval));
  last_target_ = !mass_variable.empty() ? "${" + mass_variable + "}" : f.mass ? g(*f.mass) : "";
  return (f.mass ? *f.mass : double(*f.count)) / f.rate + interval;
}

std::string LiggghtsDeck::finish_insertion(double tolerance) {
  const int k = factories_;
  if (last_interval_ > 0 && !last_target_.empty()) {
    const int l = ++loops_;
    line(fmt::format("variable inserted{} equal f_ins{}[2]", l, k));
    line(fmt::format("label batch{}", l));
    line(fmt::format("variable before{} equal ${{inserted{}}}", l, l));
    line(fmt::format("variable target{} equal {}-{}", l, last_target_, g(tolerance)));
    line(fmt::format("if \"${{inserted{}}} >= ${{target{}}}\" then \"jump SELF inserted{}\"", l, l,
                     l));
    line(fmt::format("run {}", last_interval_));
    line(fmt::format("print \"clumpkit: pouring: ${{inserted{}}} kg in\"", l));
    line(fmt::format("if \"${{inserted{}}} > ${{before{}}}\" then \"jump SELF batch{}\"", l, l, l));
    line(fmt::format("label inserted{}", l));
  }
  // An insertion all at once places its clumps at the first step after the fix.
  if (last_interval_ == 0) line("run 1");
  // What it placed, kept in a variable of its own before the fix goes.
  line(fmt::format("variable ins{}_now equal f_ins{}[2]", k, k));
  line(fmt::format("variable poured{} equal ${{ins{}_now}}", k, k));
  line(fmt::format("unfix ins{}", k));
  return fmt::format("poured{}", k);
}

void LiggghtsDeck::run(double seconds, const std::string& what) {
  if (steps(seconds) > 0) run(g(seconds), what);
}

void LiggghtsDeck::run(const std::string& seconds, const std::string& what) {
  const int k = ++loops_;
  // About 50 chunks, each ending with a progress line.
  line(fmt::format("variable left{} equal ceil(({})/{}-1e-9)", k, seconds, g(dt_)));
  line(fmt::format("variable chunk{} equal ceil(${{left{}}}/50)", k, k));
  line(fmt::format("label run{}", k));
  line(fmt::format("variable step{} equal ${{chunk{}}}", k, k));
  line(fmt::format("if \"${{left{}}} < ${{chunk{}}}\" then \"variable step{} equal ${{left{}}}\"",
                   k, k, k, k));
  line(fmt::format("if \"${{step{}}} > 0\" then \"run ${{step{}}}\"", k, k));
  line(fmt::format("variable left{} equal ${{left{}}}-${{step{}}}", k, k, k));
  line(fmt::format(
      "print \"clumpkit: {}: t = ${{now}} s, ${{left{}}} steps to go, rms speed ${{rms}} m/s\"",
      what, k));
  line(fmt::format("if \"${{left{}}} > 0\" then \"jump SELF run{}\"", k, k));
}

void LiggghtsDeck::end_block(const std::string& name, const std::string& condition) {
  // LIGGGHTS cannot `include` inside an `if`: the block is a file of its own that the main
  // script jumps to, and that jumps back to the label after the `if`.
  const std::string back = "after_" + ident(name);
  std::string text;
  for (size_t i = block_start_; i < lines_.size(); ++i) text += lines_[i] + "\n";
  text += "jump in.rig " + back + "\n";
  lines_.resize(block_start_);
  files_.push_back({name, text});
  line(fmt::format("if \"{}\" then \"jump {}\"", condition, name));
  line("label " + back);
}

void LiggghtsDeck::settle(const std::string& what, double speed, double max_seconds, double check) {
  const int k = ++loops_;
  line(fmt::format("variable quiet{} equal 0", k));
  line(fmt::format("variable until{} equal ${{now}}+{}", k, g(max_seconds)));
  line(fmt::format("label settle{}", k));
  line(fmt::format("run {}", std::max(1L, steps(check))));
  line(
      fmt::format("if \"${{rms}} < {}\" then \"variable quiet{} equal ${{quiet{}}}+1\" else "
                  "\"variable quiet{} equal 0\"",
                  g(speed), k, k, k));
  line(fmt::format("print \"clumpkit: {}: t = ${{now}} s, rms speed ${{rms}} m/s\"", what));
  line(fmt::format("if \"${{quiet{}}} >= 3\" then \"jump SELF settled{}\"", k, k));
  line(fmt::format("if \"${{now}} >= ${{until{}}}\" then \"jump SELF settled{}\"", k, k));
  line(fmt::format("jump SELF settle{}", k));
  line(fmt::format("label settled{}", k));
  line(
      fmt::format("print \"clumpkit: {}: ended at t = ${{now}} s, rms speed ${{rms}} m/s, {} "
                  "quiet checks of 3\"",
                  what, "${quiet" + std::to_string(k) + "}"));
}

void LiggghtsDeck::move_wall(const std::string& name, const Vector3d& v) {
  line(fmt::format("fix move_{} all move/mesh mesh {} linear {} {} {}", ident(name), ident(name),
                   g(v.x()), g(v.y()), g(v.z())));
}

void LiggghtsDeck::stop_wall(const std::string& name) {
  line("unfix move_" + ident(name));
}

void LiggghtsDeck::rotate_wall(const std::string& name, const Vector3d& point, const Vector3d& axis,
                               double rpm) {
  // (+ 0.0 turns the negated axis's -0 into 0.)
  const Vector3d a = (rpm < 0 ? -axis : axis).normalized() + Vector3d::Zero();
  line(fmt::format(
      "fix move_{} all move/mesh mesh {} rotate origin {} {} {} axis {} {} {} period {}",
      ident(name), ident(name), g(point.x()), g(point.y()), g(point.z()), g(a.x()), g(a.y()),
      g(a.z()), g(60.0 / std::abs(rpm))));
}

void LiggghtsDeck::write_bodies(const std::string& bodies_file) {
  if (!body_computes_) {
    line("compute body_x all rigid property xcm");
    line("compute body_m all rigid property masstotal");
    body_computes_ = true;
  }
  line(fmt::format("dump bodies all local 1 {} c_body_x[1] c_body_x[2] c_body_x[3] c_body_m",
                   bodies_file));
  line("dump_modify bodies format \"%.12g %.12g %.12g %.12g\"");
  line("run 0");
  line("undump bodies");
}

void LiggghtsDeck::write_state(const std::string& bodies_file, const std::string& spheres_file) {
  write_bodies(bodies_file);
  line(fmt::format("dump spheres all custom 1 {} id x y z radius", spheres_file));
  line("dump_modify spheres format \"%d %.12g %.12g %.12g %.12g\"");
  line("run 0");
  line("undump spheres");
}

std::vector<DeckFile> LiggghtsDeck::files() const {
  std::vector<DeckFile> out = files_;
  std::string text;
  for (const auto& l : lines_) text += l + "\n";
  out.push_back({"in.rig", text});
  return out;
}

std::vector<std::vector<double>> read_dump_rows(const std::string& path, int columns) {
  long timestep = 0;
  return read_dump_rows(path, columns, &timestep);
}

std::vector<std::vector<double>> read_dump_rows(const std::string& path, int columns,
                                                long* timestep) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "", "cannot read the LIGGGHTS dump (did the run finish?)");
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  size_t start = lines.size();
  for (size_t i = 0; i < lines.size(); ++i)
    if (lines[i].rfind("ITEM: TIMESTEP", 0) == 0) start = i;
  if (start + 9 > lines.size()) throw InputError(path, "", "no complete frame in the dump");
  long count = 0;
  try {
    *timestep = std::stol(lines[start + 1]);
  } catch (const std::exception&) {
    throw InputError(path, fmt::format("line {}", start + 2), "expected the time step number");
  }
  try {
    count = std::stol(lines[start + 3]);
  } catch (const std::exception&) {
    throw InputError(path, fmt::format("line {}", start + 4), "expected the number of entries");
  }
  std::vector<std::vector<double>> rows;
  for (long r = 0; r < count; ++r) {
    const size_t i = start + 9 + size_t(r);
    if (i >= lines.size()) throw InputError(path, "", "the last frame is cut short");
    std::istringstream ss(lines[i]);
    std::vector<double> row(static_cast<size_t>(columns), 0.0);
    for (double& x : row)
      if (!(ss >> x) || !std::isfinite(x))
        throw InputError(path, fmt::format("line {}", i + 1),
                         fmt::format("expected {} numbers", columns));
    rows.push_back(std::move(row));
  }
  return rows;
}

LiggghtsPrograms require_liggghts(int np) {
  LiggghtsPrograms p{which("liggghts"), np > 1 ? which("mpirun") : ""};
  if (p.liggghts.empty())
    throw InputError("--engine", "liggghts",
                     "LIGGGHTS is not installed (Debian: apt-get install liggghts)");
  if (np > 1 && p.mpirun.empty())
    throw InputError("--np", std::to_string(np),
                     "mpirun is not installed (Debian: apt-get install openmpi-bin)");
  return p;
}

void run_liggghts(const std::string& dir, int np,
                  const std::function<void(const std::string&)>& say) {
  const auto [liggghts, mpirun] = require_liggghts(np);
  // Line-buffered, so progress arrives as it happens and an MPI abort loses no ERROR line.
  const std::string stdbuf = which("stdbuf");
  std::string cmd = (stdbuf.empty() ? "" : shell_quote(stdbuf) + " -oL -eL ") +
                    shell_quote(liggghts) + " -in in.rig -log liggghts.log";
  if (np > 1) {
    // OpenMPI refuses root without the flag; containers often forbid its shared-memory single
    // copy (ptrace), which it then reports as an error in every exchange.
    cmd = fmt::format(
        "env OMPI_MCA_btl_vader_single_copy_mechanism=none {} {}--oversubscribe -np {} {}",
        shell_quote(mpirun), ::geteuid() == 0 ? "--allow-run-as-root " : "", np, cmd);
  }
  const std::string full = "cd " + shell_quote(dir) + " && exec " + cmd + " 2>&1";
  FILE* p = ::popen(full.c_str(), "r");
  if (!p) throw InputError("--engine", "liggghts", "cannot start " + liggghts);
  std::ofstream screen(dir + "/screen.txt");
  std::string error, line;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) {
    line += buf;
    if (line.empty() || line.back() != '\n') continue;
    screen << line;
    line.pop_back();
    if (line.rfind("clumpkit: ", 0) == 0 && say) say(line.substr(10));
    if (line.rfind("ERROR", 0) == 0 && error.empty()) error = line;
    line.clear();
  }
  const int status = ::pclose(p);
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  if (code != 0 || !error.empty())
    throw NumericalError(
        fmt::format("LIGGGHTS stopped (exit status {}){}; its output is in {}/screen.txt", code,
                    error.empty() ? "" : ": " + error, dir));
}

}  // namespace clumpkit::rigs::detail
