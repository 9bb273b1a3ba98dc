// World::set_wall_motion (added for the rigs: a scraper, lift or wheel starts once the bed has
// settled, without rebuilding the World and losing contact histories): starting a motion at run
// time equals creating the World with that motion, and checkpoints carry the new motion.
#include <gtest/gtest.h>

#include <filesystem>

#include "clumpkit/core/error.hpp"
#include "clumpkit/dem/world.hpp"
#include "dem/scenes.hpp"

namespace clumpkit::dem {
namespace {

// Balls resting on a floor with a plate (the "pusher") beside them; `motion` moves the plate.
WorldSettings scene(const WallMotion& motion) {
  WorldSettings s;
  s.source = "wall motion test";
  s.threads = 1;
  const double r = 2e-3;
  s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
  s.walls.push_back(test::floor_wall(0.2, 4));
  WallSettings pusher;
  pusher.name = "pusher";
  pusher.mesh = make_plane(Eigen::Vector3d(-0.01, 0, 0.01), Eigen::Vector3d::UnitX(), 0.03, 0.02);
  pusher.material = "organic_glass";
  pusher.motion = motion;
  s.walls.push_back(pusher);
  return s;
}

void populate(World& w) {
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 2; ++j)
      w.add_clump(0, Eigen::Vector3d(-0.006 + 0.0041 * k, 0.0041 * j, 2e-3 + 1e-5));
}

WallMotion push(double t_on) {
  WallMotion m;
  m.translation.times = {t_on, t_on + 1e-4};
  m.translation.velocities = {Eigen::Vector3d::Zero(), Eigen::Vector3d(0.05, 0, 0)};
  return m;
}

TEST(WallMotion, StartedAtRunTimeEqualsMotionFromCreation) {
  const double t_on = 0.02;
  World a = World::create(scene(push(t_on)));
  World b = World::create(scene({}));
  populate(a);
  populate(b);
  const int pusher = b.wall_index("pusher");
  b.run_until(0.01);
  a.run_until(0.01);
  EXPECT_GT(b.contact_count(), 0);  // resting on the floor: histories exist
  b.set_wall_motion(pusher, push(t_on));
  ASSERT_EQ(a.state_hash(), b.state_hash());
  const auto path = std::filesystem::path(CLUMPKIT_BINARY_DIR) / "wall_motion_test.ckpt";
  b.save_checkpoint(path);
  a.run_until(0.15);
  b.run_until(0.15);
  EXPECT_EQ(a.state_hash(), b.state_hash());
  // The plate moved and pushed the balls.
  EXPECT_GT(b.wall_vertices(pusher)[0].x(), -0.01 + 0.05 * 0.1);
  double xmax = -1;
  for (const auto& x : b.positions()) xmax = std::max(xmax, x.x());
  EXPECT_GT(xmax, 0.013);
  // A World created without the motion resumes from the checkpoint with it.
  World c = World::create(scene({}));
  c.load_checkpoint(path);
  c.run_until(0.15);
  EXPECT_EQ(c.state_hash(), b.state_hash());
  EXPECT_EQ(c.wall_vertices(pusher)[0], b.wall_vertices(pusher)[0]);
  std::filesystem::remove(path);
}

TEST(WallMotion, BadInputIsRefused) {
  World w = World::create(scene({}));
  EXPECT_THROW(w.set_wall_motion(5, push(0.0)), InputError);
  WallMotion bad;
  bad.rotation = WallRotation{};
  bad.rotation->axis = Eigen::Vector3d::Zero();
  EXPECT_THROW(w.set_wall_motion(1, bad), InputError);
}

}  // namespace
}  // namespace clumpkit::dem
