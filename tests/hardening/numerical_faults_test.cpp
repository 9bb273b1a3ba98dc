// Numerical faults (issue #8): a deliberately unstable world must stop with a NumericalError whose
// message names the cause, before any non-finite number reaches the state a caller would write
// out. Scenes through the CLI are in tests/cli/catalogue/sim.toml; these go through the library,
// where interpenetrating insertion (World::add_clump does not check overlaps) is possible.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "clumpkit/core/error.hpp"
#include "clumpkit/dem/world.hpp"

namespace clumpkit::dem {
namespace {

namespace fs = std::filesystem;

WorldSettings pills(int threads = 1) {
  WorldSettings s;
  s.source = "numerical_faults_test";
  s.clump_types.push_back(
      {"A4", load_clump(fs::path(CLUMPKIT_SOURCE_DIR) / "tests/fuzz/corpus/clump_json/A4.json"),
       "pill"});
  s.threads = threads;
  return s;
}

bool all_finite(const World& w) {
  for (int c = 0; c < w.clump_count(); ++c)
    if (!w.positions()[c].allFinite() || !w.velocities()[c].allFinite()) return false;
  return true;
}

// Runs until a NumericalError (at most `steps` steps); returns its message, "" if none.
std::string run_to_fault(World& w, int steps) {
  try {
    for (int i = 0; i < steps; ++i) w.step();
  } catch (const NumericalError& e) {
    return e.what();
  }
  return "";
}

TEST(NumericalFaults, InterpenetratingInsertionStopsWithAnOverlapDiagnosis) {
  World w = World::create(pills());
  w.add_clump(0, Eigen::Vector3d(0, 0, 0.1));
  w.add_clump(0, Eigen::Vector3d(0, 0, 0.1));  // the same place: fully interpenetrating
  const std::string msg = run_to_fault(w, 1000);
  ASSERT_FALSE(msg.empty()) << "two clumps in the same place ran on";
  EXPECT_NE(msg.find("overlap"), std::string::npos) << msg;
  EXPECT_NE(msg.find("clumps 0 and 1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("step 1,"), std::string::npos) << "not stopped at the first step: " << msg;
}

TEST(NumericalFaults, PartlyOverlappingInsertionStopsBeforeNonFiniteState) {
  // Spheres overlapping by a third of a radius: the contact force launches them; the run must
  // either settle it or stop with a diagnosis, never go on with NaN or absurd speeds.
  World w = World::create(pills());
  double r = 1e9;
  for (const Sphere& sp : w.clump_type(0).clump.spheres) r = std::min(r, sp.radius);
  // Each sphere overlaps its copy in the other clump by a third of the smallest radius.
  w.add_clump(0, Eigen::Vector3d(0, 0, 0.1));
  w.add_clump(0, Eigen::Vector3d(1.67 * r, 0, 0.1));
  const std::string msg = run_to_fault(w, 20000);
  if (msg.empty()) {
    EXPECT_TRUE(all_finite(w));
    for (int c = 0; c < w.clump_count(); ++c) EXPECT_LT(w.velocities()[c].norm(), 50.0);
  } else {
    EXPECT_TRUE(msg.find("overlap") != std::string::npos ||
                msg.find("blew up") != std::string::npos ||
                msg.find("unstable") != std::string::npos)
        << msg;
  }
}

TEST(NumericalFaults, TimeStepAboveTheStabilityLimitIsRefused) {
  WorldSettings s = pills();
  s.time_step = 1e-3;  // hundreds of Rayleigh times
  try {
    (void)World::create(s);
    FAIL() << "a time step far above the stability limit was accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("time_step"), std::string::npos) << msg;
    EXPECT_NE(msg.find("above the stability limit"), std::string::npos) << msg;
  }
}

TEST(NumericalFaults, TimeStepAboveTheDampingLimitIsRefusedAtCreation) {
  // With implicit damping off: the Hertz check passes with a tiny expected impact speed (the
  // override); the contact damping's rate does not depend on it much, and 1e-4 s is above
  // 2/rate. (With it on, the default, such a step is stable: implicit_damping_test.)
  WorldSettings s = pills();
  s.implicit_damping = 0.0;
  s.time_step = 1e-4;
  s.max_impact_speed = 1e-6;
  try {
    (void)World::create(s);
    FAIL() << "a time step above the damping limit was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "time_step");
    EXPECT_NE(std::string(e.what()).find("damping"), std::string::npos) << e.what();
  }
}

TEST(NumericalFaults, TimeStepForcedAboveTheLimitStopsWithADiagnosis) {
  // Undamped (elastic) pills: no damping limit. The Hertz check passes with a tiny expected
  // impact speed (the override): the run itself must then catch the instability.
  WorldSettings s = pills();
  s.time_step = 1e-4;
  s.max_impact_speed = 1e-6;
  PairContact elastic = PairContact::from(s.materials.interaction("pill", "pill"));
  elastic.restitution.reset();
  s.pair_contacts.push_back({"pill", "pill", elastic});
  PairContact wall = PairContact::from(s.materials.interaction("pill", "galvanized_steel"));
  wall.restitution.reset();
  s.pair_contacts.push_back({"pill", "galvanized_steel", wall});
  s.walls.push_back({"floor",
                     make_plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.1, 0.1),
                     "galvanized_steel",
                     {},
                     {}});
  World w = World::create(s);
  EXPECT_FALSE(w.warnings().empty()) << "no warning for a time step far above the Rayleigh time";
  for (int i = 0; i < 5; ++i)
    w.add_clump(0, Eigen::Vector3d(0.012 * i - 0.024, 0, 0.004), Eigen::Quaterniond::Identity(),
                Eigen::Vector3d(0, 0, -0.5));
  const std::string msg = run_to_fault(w, 100000);
  ASSERT_FALSE(msg.empty()) << "the unstable run went on; finite state: " << all_finite(w);
  EXPECT_NE(msg.find("time step 0.0001 s"), std::string::npos) << msg;
  EXPECT_TRUE(msg.find("overlap") != std::string::npos ||
              msg.find("blew up") != std::string::npos || msg.find("unstable") != std::string::npos)
      << msg;
}

}  // namespace
}  // namespace clumpkit::dem
