// RigSimulator's cache with the real rigs: a run that fails is kept as a failure, so the same
// request fails again from the cache and a second diagnosis simulates nothing; runs made side by
// side, one repeat per task, are the runs made one by one.
#include "clumpkit/calibrate/simulator.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "clumpkit/core/error.hpp"
#include "clumpkit/core/materials.hpp"
#include "clumpkit/rigs/model.hpp"

namespace {

using namespace clumpkit;
using namespace clumpkit::calibrate;
namespace fs = std::filesystem;

// A tiny heap whose pills stick so hard that they pass through each other within a fraction of a
// second (0.2 s of wall time): a NumericalError from the real rig.
ParticleModel sticky_model() {
  ParticleModel m =
      load_model(CLUMPKIT_SOURCE_DIR "/shapes/models/paper_A12.toml", CLUMPKIT_SOURCE_DIR);
  set_model_effect(m, "effects.cohesion", "1e6 J/m^3", "test");
  return m;
}

std::string failure_of(RigSimulator& sim, const ParticleModel& m, const SimRequest& r,
                       int repeats = 1) {
  try {
    sim.simulate(m, r, repeats, 1);
  } catch (const NumericalError& e) {
    return e.what();
  }
  return "";
}

TEST(RigSimulator, AFailedRunIsCachedAndFailsAgainWithoutARun) {
  const fs::path cache = fs::temp_directory_path() / "clumpkit_simulator_test_cache";
  fs::remove_all(cache);
  const ParticleModel m = sticky_model();
  const SimRequest r{"angle_of_repose", "A", {{"scale", "tiny"}}};
  RigSimulator::Options o;
  o.cache_dir = cache;
  o.threads = 1;
  {
    RigSimulator first(o);
    const std::string why = failure_of(first, m, r);
    ASSERT_NE(why.find("overlap of"), std::string::npos) << why;
    EXPECT_EQ(first.runs(), 1);
    // Asked again by the same simulator (as a diagnosis does after its prefetch): from its
    // cache, no new run, the same message.
    EXPECT_EQ(failure_of(first, m, r), why);
    EXPECT_EQ(first.runs(), 1);
  }
  RigSimulator second(o);
  second.prefetch({{m, r}}, 1, 1);  // nothing to run: the failure is known
  const std::string again = failure_of(second, m, r);
  EXPECT_NE(again.find("overlap of"), std::string::npos) << again;
  EXPECT_NE(again.find("a cached failure"), std::string::npos) << again;
  EXPECT_EQ(second.runs(), 0);
  EXPECT_EQ(second.cache_hits(), 1);
  // Another seed is another run.
  try {
    second.simulate(m, r, 1, 2);
  } catch (const NumericalError&) {
  }
  EXPECT_EQ(second.runs(), 1);
  fs::remove_all(cache);
}

// Pill A (12 spheres) with the pill's Young's modulus lowered to 1e7 Pa, as the calibration
// loop tests run it: a tiny heap in ~3 s.
ParticleModel soft_model() {
  ParticleModel m =
      load_model(CLUMPKIT_SOURCE_DIR "/shapes/models/paper_A12.toml", CLUMPKIT_SOURCE_DIR);
  Material pill = m.materials.get("pill");
  pill.youngs_modulus = 1e7;
  m.materials.add(pill);
  return m;
}

// Two heaps of two repeats each, made by prefetch() two tasks at a time (the four repeats side
// by side), give the values the same runs give made one by one, to the last bit; so does the
// failure of a run whose repeats blow up, with the same message.
TEST(RigSimulator, RepeatsRunSideBySideAreTheRunsMadeOneByOne) {
  const fs::path root = fs::temp_directory_path() / "clumpkit_simulator_side_by_side";
  fs::remove_all(root);
  const ParticleModel m = soft_model();
  const std::vector<SimRequest> rs = {
      {"angle_of_repose", "A", {{"plate", "galvanized_steel"}, {"scale", "tiny"}}},
      {"angle_of_repose", "A", {{"plate", "organic_glass"}, {"scale", "tiny"}}}};
  RigSimulator::Options o;
  o.threads = 1;
  o.cache_dir = root / "side_by_side";
  o.jobs = 2;
  RigSimulator side(o);
  side.prefetch({{m, rs[0]}, {m, rs[1]}}, 2, 1);
  EXPECT_EQ(side.runs(), 2);  // a run is a request with all its repeats, as before
  o.cache_dir = root / "one_by_one";
  o.jobs = 1;
  RigSimulator alone(o);
  for (const SimRequest& r : rs) {
    const SimValues a = side.simulate(m, r, 2, 1);  // from the prefetch
    const SimValues b = alone.simulate(m, r, 2, 1);
    ASSERT_EQ(a.size(), 3u);  // angle, angle_left, angle_right
    ASSERT_EQ(a.size(), b.size());
    for (const auto& [q, v] : b) {
      EXPECT_EQ(a.at(q).n, 2) << q;
      EXPECT_EQ(a.at(q).mean, v.mean) << r.key() << " " << q;
      EXPECT_EQ(a.at(q).std, v.std) << r.key() << " " << q;
      EXPECT_GT(v.std, 0.0) << q;  // two seeds, two heaps
    }
  }
  EXPECT_EQ(side.runs(), 2);
  EXPECT_EQ(alone.runs(), 2);

  const ParticleModel sticky = sticky_model();
  // Its two repeats side by side, both blow up: the failure is rethrown, and kept.
  EXPECT_THROW(side.prefetch({{sticky, rs[0]}}, 2, 1), NumericalError);
  const std::string together = failure_of(side, sticky, rs[0], 2);
  const std::string by_itself = failure_of(alone, sticky, rs[0], 2);
  EXPECT_NE(together.find("repeat 1 (seed 1)"), std::string::npos) << together;
  EXPECT_EQ(together, by_itself);
  EXPECT_EQ(side.runs(), 3);
  fs::remove_all(root);
}

}  // namespace
