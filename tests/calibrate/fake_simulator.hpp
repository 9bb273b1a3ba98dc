#pragma once
// A fast analytic stand-in for the rigs, for testing the diagnosis logic: each effect moves the
// observables in its own direction (CALIBRATION.md's "fingerprints"), responses are nonlinear,
// and every run carries seeded noise (common random numbers: the same seed gives the same noise).
#include <cmath>
#include <functional>
#include <random>

#include "clumpkit/calibrate/simulator.hpp"

namespace clumpkit::calibrate::fake {

class FakeSimulator final : public Simulator {
 public:
  double noise_rel = 0.004;  // relative std of one repeat
  // true: the same seed gives the same noise whatever the model (ideal common random numbers);
  // false: every model draws its own noise, as a chaotic granular flow does when a parameter
  // changes a little (the rigs' runs decorrelate quickly).
  bool common_random_numbers = true;
  // Relative std of a scatter that every repeat of one model shares (0: none): a variant's
  // repeats then agree more closely than its mean agrees with a smooth response, so their
  // spread understates how far the mean of a nearby variant can be.
  double variant_noise_rel = 0.0;
  std::uint64_t variant_seed = 0;  // which shared scatter each model gets

  SimValues simulate(const ParticleModel& model, const SimRequest& r, int repeats,
                     std::uint64_t seed) override {
    ++runs_;
    const ModelEffects& e = model.effects;
    auto partner = [](const std::optional<std::map<std::string, double>>& v, const std::string& k) {
      return v && v->count(k) ? v->at(k) : 0.0;
    };
    const double mur = partner(e.rolling_friction, "pill");
    const double mus = e.particle_friction.value_or(0.0);
    const double e_pp = partner(e.restitution, "pill") > 0 ? partner(e.restitution, "pill") : 1.0;
    const double coh = e.cohesion.value_or(0.0);
    const double spread = e.size_distribution ? e.height_spread : 0.0;
    // A mixture's first type (in a model of several) packs denser, heaps a little steeper and
    // fills a pocket less than the others.
    const double mix = model.types.size() > 1 ? model.types.front().mass_fraction - 0.5 : 0.0;
    const int spheres = e.shape_resolution.value_or(model.types.front().paper_spheres.value_or(12));
    const std::string wall = r.settings.count("wall")    ? r.settings.at("wall")
                             : r.settings.count("plate") ? r.settings.at("plate")
                                                         : "abs_plastic";
    const double muw = partner(e.wall_friction, wall);
    std::map<std::string, double> mean;
    if (r.rig == "bulk_density") {
      // Rolling friction changes the packing little; cohesion opens it up (CALIBRATION.md); a
      // spread of pill heights packs a little denser.
      mean["bulk_density"] = 760 - 120 * std::tanh(mus) - 10 * mur - 4e-3 * coh - 40 * muw +
                             15 * (e_pp - 0.5) + 2.0 * (spheres - 12) + 150 * spread + 60 * mix;
    } else if (r.rig == "angle_of_repose") {
      // A free heap: wall (plate) friction matters little, cohesion and rolling friction a lot.
      const double a = 14 + 25 * std::tanh(2 * mur) + 8 * mus + 1.2e-3 * coh +
                       1.5 * std::tanh(muw) - 0.3 * (20 - spheres) + 2 * (0.5 - e_pp) -
                       10 * spread + 3 * mix;
      mean["angle"] = a;
      mean["angle_left"] = a + 0.2;
      mean["angle_right"] = a - 0.2;
    } else {
      const double rpm = std::stod(r.settings.at("rpm"));
      mean["pocket_mass"] = 0.25 - 0.0008 * (rpm - 10) - 0.02 * muw - 0.01 * mur - 4e-7 * coh +
                            0.05 * spread - 0.03 * mix;
      mean["pocket_mass_cv"] = 0.03 + 0.0004 * std::abs(rpm - 15) + 0.01 * mur;
      mean["mass_flow"] = mean["pocket_mass"] * 8 * rpm / 60;
    }
    SimValues out;
    for (const auto& [q, m] : mean) {
      const std::string salt = common_random_numbers ? "" : model_fingerprint(model);
      std::seed_seq ss{seed, std::hash<std::string>{}(r.key() + q + salt)};
      std::mt19937_64 rng(ss);
      std::normal_distribution<double> g(0.0, noise_rel * std::abs(m));
      double shared = 0.0;
      if (variant_noise_rel > 0.0) {
        std::seed_seq vs{variant_seed,
                         std::hash<std::string>{}(r.key() + q + model_fingerprint(model))};
        std::mt19937_64 vr(vs);
        shared = std::normal_distribution<double>(0.0, variant_noise_rel * std::abs(m))(vr);
      }
      std::vector<double> v;
      for (int k = 0; k < repeats; ++k) v.push_back(m + shared + g(rng));
      out[q] = summarize(v);
    }
    return out;
  }
};

// The stand-in with a test's own response added: `adjust` changes the values of a run of `model`
// (the model as asked for, before `strip` takes from it what the stand-in must not see).
class Adjusted final : public Simulator {
 public:
  FakeSimulator inner;
  std::function<void(const ParticleModel&, const SimRequest&, int repeats, SimValues&)> adjust;
  std::function<void(ParticleModel&)> strip = [](ParticleModel&) {};

  SimValues simulate(const ParticleModel& model, const SimRequest& r, int repeats,
                     std::uint64_t seed) override {
    ++runs_;
    ParticleModel m = model;
    strip(m);
    SimValues v = inner.simulate(m, r, repeats, seed);
    adjust(model, r, repeats, v);
    return v;
  }
};

}  // namespace clumpkit::calibrate::fake
