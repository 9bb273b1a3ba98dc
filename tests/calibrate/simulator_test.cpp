// RigSimulator's cache with the real rigs: a run that fails is kept as a failure, so the same
// request fails again from the cache and a second diagnosis simulates nothing.
#include "clumpkit/calibrate/simulator.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "clumpkit/core/error.hpp"
#include "clumpkit/rigs/model.hpp"

namespace {

using namespace clumpkit;
using namespace clumpkit::calibrate;
namespace fs = std::filesystem;

// A tiny heap whose pills stick so hard that the contact forces blow up within a fraction of a
// second (0.2 s of wall time): a NumericalError from the real rig.
ParticleModel sticky_model() {
  ParticleModel m =
      load_model(CLUMPKIT_SOURCE_DIR "/shapes/models/paper_A12.toml", CLUMPKIT_SOURCE_DIR);
  set_model_effect(m, "effects.cohesion", "1e6 J/m^3", "test");
  return m;
}

std::string failure_of(RigSimulator& sim, const ParticleModel& m, const SimRequest& r) {
  try {
    sim.simulate(m, r, 1, 1);
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
    ASSERT_NE(why.find("unstable"), std::string::npos) << why;
    EXPECT_EQ(first.runs(), 1);
    // Asked again by the same simulator (as a diagnosis does after its prefetch): from its
    // cache, no new run, the same message.
    EXPECT_EQ(failure_of(first, m, r), why);
    EXPECT_EQ(first.runs(), 1);
  }
  RigSimulator second(o);
  second.prefetch({{m, r}}, 1, 1);  // nothing to run: the failure is known
  const std::string again = failure_of(second, m, r);
  EXPECT_NE(again.find("unstable"), std::string::npos) << again;
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

}  // namespace
