#include "clumpkit/calibrate/simulator.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <algorithm>
#include <set>
#include <sstream>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/rigs/catalogue.hpp"
#include "clumpkit/rigs/rig.hpp"

namespace clumpkit::calibrate {

namespace fs = std::filesystem;
using nlohmann::json;

std::string SimRequest::key() const { return rig + "|" + sample + "|" + format_settings(settings); }

ParticleModel model_for_sample(const ParticleModel& model, const std::string& sample,
                               const std::string& where) {
  if (sample == "mix") return model;
  ParticleModel m = model;
  m.types.clear();
  std::string known;
  for (const auto& t : model.types) {
    known += (known.empty() ? "" : ", ") + t.name;
    if (t.name == sample) {
      m.types.push_back(t);
      m.types.back().mass_fraction = 1.0;
    }
  }
  if (m.types.empty())
    throw InputError(where, "sample",
                     "model '" + model.name + "' has no pill type '" + sample + "' (types: " + known +
                         "; use sample 'mix' for the whole population)");
  if (m.types.size() < model.types.size()) m.effects.size_distribution = false;
  return m;
}

std::vector<SimRequest> requests_for(const std::vector<Measurement>& ms, const std::string& scale) {
  std::vector<SimRequest> out;
  std::set<std::string> seen;
  for (const auto& m : ms) {
    SimRequest r{m.rig, m.sample, m.setting};
    if (!r.settings.count("scale")) r.settings["scale"] = scale;
    if (seen.insert(r.key()).second) out.push_back(r);
  }
  return out;
}

SimValues to_canonical(const std::string& rig, const std::map<std::string, double>& mean_si,
                       const std::map<std::string, double>& std_si, int n) {
  const RigInfo& info = find_rig(rig);
  SimValues v;
  for (const auto& q : info.quantities) {
    auto it = mean_si.find(q.name);
    if (it == mean_si.end()) continue;
    SimulatedValue s;
    s.mean = it->second / q.to_si;
    auto sd = std_si.find(q.name);
    s.std = sd == std_si.end() ? 0.0 : sd->second / q.to_si;
    s.n = n;
    v[q.name] = s;
  }
  return v;
}

std::map<std::string, SimulatedValue> simulate_measurements(Simulator& sim,
                                                            const ParticleModel& model,
                                                            const std::vector<Measurement>& ms,
                                                            const std::string& scale, int repeats,
                                                            std::uint64_t seed) {
  std::map<std::string, SimValues> by_request;
  for (const SimRequest& r : requests_for(ms, scale))
    by_request[r.key()] = sim.simulate(model, r, repeats, seed);
  std::map<std::string, SimulatedValue> out;
  for (const auto& m : ms) {
    SimRequest r{m.rig, m.sample, m.setting};
    if (!r.settings.count("scale")) r.settings["scale"] = scale;
    const SimValues& v = by_request.at(r.key());
    auto it = v.find(m.quantity);
    if (it == v.end())
      throw NumericalError("rig " + m.rig + " produced no value of " + m.quantity);
    out[m.key()] = it->second;
  }
  return out;
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
    if (!t.clump_path.empty()) s << read_file(t.clump_path).size() << ":" << std::hash<std::string>{}(read_file(t.clump_path));
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
  s << "particle_friction " << (e.particle_friction ? fmt::format("{:.17g}", *e.particle_friction) : "absent") << "\n";
  s << "cohesion " << (e.cohesion ? fmt::format("{:.17g}", *e.cohesion) : "absent") << "\n";
  s << "shape_resolution " << e.shape_resolution.value_or(0) << "\n";
  s << "size_distribution " << e.size_distribution << "\n";
  s << "rolling_model " << (e.rolling_model ? dem::to_string(*e.rolling_model) : "default") << " "
    << e.epsd_damping << "\n";
  return s.str();
}

RigSimulator::RigSimulator(Options options) : opt_(std::move(options)) {}

SimValues RigSimulator::simulate(const ParticleModel& model, const SimRequest& req, int repeats,
                                 std::uint64_t seed) {
  const ParticleModel m = model_for_sample(model, req.sample, model.path.string());
  const std::string fp = model_fingerprint(m);
  const std::string key = fmt::format("{}|{}|{}|{}", req.key(), seed, repeats, fp);
  const std::string id = fmt::format("{:016x}", std::hash<std::string>{}(key));
  const fs::path file = opt_.cache_dir / (req.rig + "_" + id + ".json");
  const fs::path run_dir = opt_.cache_dir / ("run_" + req.rig + "_" + id);
  folders_.push_back(run_dir);
  std::error_code ec;
  if (fs::exists(file, ec)) {
    try {
      const json j = json::parse(read_file(file));
      if (j.value("key", "") == key) {
        ++hits_;
        SimValues v;
        for (const auto& [q, x] : j.at("values").items())
          v[q] = {x.at("mean").get<double>(), x.at("std").get<double>(), x.at("n").get<int>()};
        return v;
      }
    } catch (const std::exception&) {
      // A damaged cache entry is recomputed.
    }
  }
  fs::create_directories(opt_.cache_dir, ec);
  rigs::RigRequest rr;
  rr.rig = req.rig;
  rr.model = m;
  rr.settings = req.settings;
  rr.repeats = repeats;
  rr.seed = seed;
  rr.threads = opt_.threads;
  rr.rays = opt_.rays;
  rr.out = run_dir;
  rr.progress = opt_.progress;
  if (opt_.progress)
    opt_.progress(fmt::format("simulating {} sample {} [{}] model {} x{}", req.rig, req.sample,
                              format_settings(req.settings), model.name, repeats));
  const rigs::RigResult r = rigs::run_rig(rr);
  if (!r.error.empty())
    throw NumericalError(fmt::format("rig {} for model {} failed: {}", req.rig, model.name, r.error));
  ++runs_;
  std::map<std::string, double> mean, sd;
  int n = 0;
  for (const auto& [q, st] : r.stats) {
    mean[q] = st.mean;
    sd[q] = st.std;
    n = st.n;
  }
  SimValues v = to_canonical(req.rig, mean, sd, n);
  json values = json::object();
  for (const auto& [q, x] : v) values[q] = {{"mean", x.mean}, {"std", x.std}, {"n", x.n}};
  write_file_atomic(file, json{{"key", key}, {"values", values}, {"result", r.to_json()}}.dump(1));
  return v;
}

std::vector<fs::path> RigSimulator::pictures() const {
  std::vector<fs::path> out;
  std::set<fs::path> seen;
  for (const auto& d : folders_) {
    std::error_code ec;
    if (!seen.insert(d).second || !fs::is_directory(d, ec)) continue;
    for (const auto& e : fs::recursive_directory_iterator(d, ec))
      if (e.path().extension() == ".png") out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace clumpkit::calibrate
