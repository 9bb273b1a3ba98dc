// The DEM step under two threads: a TSan workload (small: TSan is 5-15x slower) that also asserts
// the documented determinism (docs/dem.md): the same world stepped with 1 and with 2 threads
// ends in bit-identical states (equal state hashes). 20 pills poured into a box with moving walls
// exercise the threaded contact, wall and integration loops.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "clumpkit/dem/world.hpp"

namespace clumpkit::dem {
namespace {

namespace fs = std::filesystem;

std::uint64_t run(int threads) {
  WorldSettings s;
  s.source = "dem_threads_test";
  s.clump_types.push_back(
      {"A4", load_clump(fs::path(CLUMPKIT_SOURCE_DIR) / "tests/fuzz/corpus/clump_json/A4.json"),
       "pill"});
  s.threads = threads;
  s.seed = 5;
  s.rayleigh_fraction = 0.3;
  WallSettings box{
      "box",
      make_box(Eigen::Vector3d(-0.012, -0.012, 0), Eigen::Vector3d(0.012, 0.012, 0.04)),
      "galvanized_steel",
      {},
      {}};
  s.walls.push_back(box);
  WallSettings paddle{
      "paddle",
      make_plane(Eigen::Vector3d(0, 0, 0.003), Eigen::Vector3d::UnitX(), 0.02, 0.006),
      "abs_plastic",
      {},
      {}};
  WallRotation r;
  r.rpm = 60;
  r.axis = Eigen::Vector3d::UnitZ();
  paddle.motion.rotation = r;
  s.walls.push_back(paddle);
  FactorySettings f;
  f.region = BoxRegion{Eigen::Vector3d(-0.01, -0.01, 0.005), Eigen::Vector3d(0.01, 0.01, 0.035)};
  f.count = 20;
  f.mixture = {{"A4", 1.0}};
  f.velocity = Eigen::Vector3d(0, 0, -1.0);
  s.factories.push_back(f);
  World w = World::create(s);
  int most = 0;
  for (int i = 0; i < 3000; ++i) {
    w.step();
    most = std::max(most, w.contact_count());
  }
  EXPECT_EQ(w.clump_count(), 20);
  EXPECT_GT(most, 0) << "the workload should have contacts";
  return w.state_hash();
}

TEST(DemThreads, TwoThreadsGiveTheSameStateAsOne) {
  EXPECT_EQ(run(1), run(2));
}

}  // namespace
}  // namespace clumpkit::dem
