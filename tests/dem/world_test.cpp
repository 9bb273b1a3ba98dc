// World-level behaviour: determinism across thread counts, checkpoint/resume, factories,
// time-step checks and blow-up detection.
#include <gtest/gtest.h>

#include <filesystem>

#include "clumpkit/core/error.hpp"
#include "clumpkit/dem/time_step.hpp"
#include "scenes.hpp"

namespace clumpkit::dem {
namespace {

// A 4-sphere "pill" (two rings of two) with set mass properties, radius r.
ClumpTypeSettings pill4(const std::string& name, double r, double h) {
  Spheres s;
  for (int k = 0; k < 4; ++k)
    s.push_back({Eigen::Vector3d((k & 1) ? r : -r, 0.0, (k & 2) ? h : -h), r});
  const double m = 4.0 * 4.0 / 3.0 * std::numbers::pi * r * r * r * 1380.0;
  return test::clump_type(
      name, s, m,
      Eigen::Vector3d(m * (h * h + 0.4 * r * r), m * (r * r + h * h + 0.4 * r * r),
                      m * (r * r + 0.4 * r * r)));
}

// A pour of a few hundred 4-sphere pills from a box factory into an open-topped box.
WorldSettings pour(int threads, std::uint64_t seed = 7) {
  WorldSettings s;
  s.source = "pour";
  s.threads = threads;
  s.seed = seed;
  s.clump_types = {pill4("A", 1.0e-3, 0.6e-3), pill4("B", 1.0e-3, 0.9e-3)};
  TriangleMesh cup =
      make_box(Eigen::Vector3d(-0.012, -0.012, 0), Eigen::Vector3d(0.012, 0.012, 0.06));
  s.walls.push_back({"cup", cup, "organic_glass", {}, {}});
  FactorySettings f;
  f.name = "hopper";
  f.region = BoxRegion{Eigen::Vector3d(-0.011, -0.011, 0.0), Eigen::Vector3d(0.011, 0.011, 0.055)};
  f.mixture = {{"A", 0.5}, {"B", 0.5}};
  f.count = 200;
  f.velocity = Eigen::Vector3d(0, 0, -0.2);
  s.factories.push_back(f);
  s.max_impact_speed = 1.0;
  return s;
}

// Stirs the pour so that clumps collide from the first steps.
void stir(World& w) {
  for (int c = 0; c < w.clump_count(); ++c) {
    w.set_velocity(c, 0.4 * Eigen::Vector3d(std::sin(1.0 * c), std::cos(1.3 * c), -0.5));
    w.set_omega_world(c, Eigen::Vector3d(20.0 * std::sin(0.7 * c), 10.0, 0.0));
  }
}

TEST(World, SameSeedSameHashForOneAndTwoThreads) {
  World a = World::create(pour(1));
  World b = World::create(pour(2));
  ASSERT_EQ(a.clump_count(), 200);
  ASSERT_GE(a.sphere_count(), 800);
  EXPECT_EQ(a.state_hash(), b.state_hash());
  stir(a);
  stir(b);
  long contacts = 0;
  for (int k = 0; k < 600; ++k) {
    a.step();
    b.step();
    contacts += a.contact_count();
  }
  EXPECT_GT(contacts, 2000) << "the scene should exercise contacts";
  EXPECT_EQ(a.state_hash(), b.state_hash());
  World c = World::create(pour(2, 8));
  for (int k = 0; k < 10; ++k) c.step();
  EXPECT_NE(a.state_hash(), c.state_hash());
}

// The neighbour list is a cache: which pairs it holds beyond the touching ones, and how often it
// is rebuilt, must not change a bit of the trajectory. A skin of 3 % of the radius (cells just
// over a diameter, a rebuild every few steps), the default, and four radii (cells of six radii)
// bin the spheres into different cells and pair them from different cells; a pair missed at a
// cell boundary, or listed twice, would change the hash.
TEST(World, NeighbourSkinAndCellsDoNotChangeTheTrajectory) {
  std::vector<std::uint64_t> hashes;
  std::vector<long> rebuilds;
  for (double skin : {3e-5, 0.0, 4e-3})
    for (int threads : {1, 2}) {
      WorldSettings s = pour(threads);
      s.skin = skin;
      World w = World::create(s);
      stir(w);
      for (int k = 0; k < 400; ++k) w.step();
      hashes.push_back(w.state_hash());
      rebuilds.push_back(w.profile().neighbour_rebuilds);
    }
  for (size_t k = 1; k < hashes.size(); ++k) EXPECT_EQ(hashes[k], hashes[0]) << "run " << k;
  EXPECT_GT(rebuilds[0], 4 * rebuilds[2]) << "the skins should differ in their rebuilds";
}

// The search before a rebuild (WorldSettings::neighbour_search) spares rebuilds the
// displacement bound asks for, and must spare none where a touching pair is missing: a missed
// pair drops a contact and changes the hash. Without gravity, pills of radius r in rows along x:
// each row has two pills flying head-on at each other, 1.5 skins apart (not listed together),
// and pills at rest. The bound fires when the two have closed one skin; the search spares the
// rebuild until they touch, then it must call for it. With 12 rows at their own speeds the
// few far-moved clumps' sphere pairs are tested directly; with 60 rows at one speed (120 fliers
// moving at once, a fifth of the spheres) the bins are searched. The runs without the search,
// on 1 and 2 threads, give the reference.
TEST(World, NeighbourSearchSparesRebuildsWithoutChangingTheTrajectory) {
  const double r = 1.0e-3, skin = 0.3 * r;
  for (int rows : {12, 60}) {
    std::vector<std::uint64_t> hashes;
    std::vector<Profile> profiles;
    for (bool search : {false, true})
      for (int threads : {1, 2}) {
        WorldSettings s;
        s.source = "head-on";
        s.threads = threads;
        s.gravity = Eigen::Vector3d::Zero();
        s.clump_types = {pill4("A", r, 0.6 * r)};
        s.max_impact_speed = 2.0;
        s.skin = skin;
        s.neighbour_search = search;
        World w = World::create(s);
        for (int row = 0; row < rows; ++row) {
          // m/s: with 12 rows each its own, with 60 one for all (every flier fast at once)
          const double y = 3.0 * r * row, v = rows == 12 ? 0.5 + 0.01 * row : 0.6;
          // Pills span 4r in x: surfaces 1.5 skins apart, then the resting ones 6r apart.
          w.add_clump(0, Eigen::Vector3d(0, y, 0), Eigen::Quaterniond::Identity(),
                      Eigen::Vector3d(v, 0, 0));
          w.add_clump(0, Eigen::Vector3d(4 * r + 1.5 * skin, y, 0), Eigen::Quaterniond::Identity(),
                      Eigen::Vector3d(-v, 0, 0));
          for (int k = 1; k <= 8; ++k) w.add_clump(0, Eigen::Vector3d(4 * r + 10 * r * k, y, 0));
        }
        long contacts = 0;
        for (int k = 0; k < (rows == 12 ? 1500 : 400); ++k) {
          w.step();
          contacts += w.contact_count();
        }
        EXPECT_GT(contacts, 10 * rows) << "the pills of each row should collide";
        hashes.push_back(w.state_hash());
        profiles.push_back(w.profile());
      }
    for (size_t k = 1; k < hashes.size(); ++k)
      EXPECT_EQ(hashes[k], hashes[0]) << rows << " rows, run " << k;
    for (size_t k = 0; k < 2; ++k) {
      const Profile &off = profiles[k], &on = profiles[k + 2];
      EXPECT_EQ(off.neighbour_rebuilds_spared, 0);
      EXPECT_GT(on.neighbour_rebuilds_spared, 10) << rows << " rows, run " << k;
      // (At one speed every row closes at once: one rebuild is needed either way.)
      if (rows == 12)
        EXPECT_LT(on.neighbour_rebuilds, off.neighbour_rebuilds) << rows << " rows, run " << k;
      else
        EXPECT_LE(on.neighbour_rebuilds, off.neighbour_rebuilds) << rows << " rows, run " << k;
    }
  }
}

// The search needs no bins when few clumps moved far (the direct test), and a checkpoint holds
// the list and the positions it was built at: a run resumed mid-flight spares the rebuilds the
// uninterrupted run spares after that point, and ends in the same state.
TEST(World, NeighbourSearchRightAfterACheckpointIsLoaded) {
  const auto path = std::filesystem::path(CLUMPKIT_BINARY_DIR) / "dem_search_checkpoint.bin";
  const double r = 1.0e-3, skin = 0.3 * r;
  WorldSettings s;
  s.source = "head-on";
  s.threads = 1;
  s.gravity = Eigen::Vector3d::Zero();
  s.clump_types = {pill4("A", r, 0.6 * r)};
  s.max_impact_speed = 2.0;
  s.skin = skin;
  auto rows = [&](World& w) {
    for (int row = 0; row < 12; ++row) {
      const double y = 3.0 * r * row, v = 0.5 + 0.01 * row;
      w.add_clump(0, Eigen::Vector3d(0, y, 0), Eigen::Quaterniond::Identity(),
                  Eigen::Vector3d(v, 0, 0));
      w.add_clump(0, Eigen::Vector3d(4 * r + 1.5 * skin, y, 0), Eigen::Quaterniond::Identity(),
                  Eigen::Vector3d(-v, 0, 0));
      for (int k = 1; k <= 8; ++k) w.add_clump(0, Eigen::Vector3d(4 * r + 10 * r * k, y, 0));
    }
  };
  World a = World::create(s);
  rows(a);
  for (int k = 0; k < 300; ++k) a.step();
  a.save_checkpoint(path);
  const Profile at_save = a.profile();
  for (int k = 0; k < 1200; ++k) a.step();

  World b = World::create(s);
  rows(b);
  b.load_checkpoint(path);
  for (int k = 0; k < 1200; ++k) b.step();
  std::filesystem::remove(path);
  EXPECT_EQ(a.state_hash(), b.state_hash());
  const long spared_after =
      a.profile().neighbour_rebuilds_spared - at_save.neighbour_rebuilds_spared;
  const long rebuilt_after = a.profile().neighbour_rebuilds - at_save.neighbour_rebuilds;
  EXPECT_GT(spared_after, 10);
  EXPECT_EQ(b.profile().neighbour_rebuilds_spared, spared_after);
  EXPECT_EQ(b.profile().neighbour_rebuilds, rebuilt_after);
}

TEST(World, CheckpointResumeIsBitIdentical) {
  const auto path = std::filesystem::path(CLUMPKIT_BINARY_DIR) / "dem_checkpoint_test.bin";
  World a = World::create(pour(1));
  stir(a);
  for (int k = 0; k < 400; ++k) a.step();
  a.save_checkpoint(path);
  for (int k = 0; k < 300; ++k) a.step();

  World b = World::create(pour(1));
  b.load_checkpoint(path);
  EXPECT_EQ(b.step_count(), 400);
  for (int k = 0; k < 300; ++k) b.step();
  EXPECT_EQ(a.state_hash(), b.state_hash());
  EXPECT_GT(a.contact_count(), 0);

  WorldSettings other = pour(1);
  other.seed = 99;
  World c = World::create(other);
  EXPECT_THROW(c.load_checkpoint(path), InputError);
  std::filesystem::remove(path);
}

// The same mid-motion: the cup rises at 5 cm/s and clumps are culled now and then (as the
// rigs do), with the checkpoint taken between a cull and the next step.
TEST(World, CheckpointResumeIsBitIdenticalWithAMovingWallAndCulls) {
  const auto path = std::filesystem::path(CLUMPKIT_BINARY_DIR) / "dem_checkpoint_moving_test.bin";
  WorldSettings s = pour(1);
  auto cull = [](World& w, double x) {
    return w.remove_clumps([&](int c) { return w.positions()[c].x() > x; });
  };
  World a = World::create(s);
  stir(a);
  for (int k = 0; k < 100; ++k) a.step();
  // The rigs start a wall's motion at run time, and stop it early (the tube cleared the heap).
  WallMotion lift;
  lift.translation = {{a.time() + 1e-4, 1.0},
                      {Eigen::Vector3d(0, 0, 0.05), Eigen::Vector3d::Zero()}};
  a.set_wall_motion(0, lift);
  for (int k = 0; k < 200; ++k) a.step();
  EXPECT_GT(cull(a, 0.009), 0);
  for (int k = 0; k < 100; ++k) a.step();
  EXPECT_GT(cull(a, 0.008), 0);
  a.save_checkpoint(path);
  for (int k = 0; k < 200; ++k) a.step();
  cull(a, 0.006);
  for (int k = 0; k < 300; ++k) a.step();

  World b = World::create(s);
  b.load_checkpoint(path);
  for (int k = 0; k < 200; ++k) b.step();
  cull(b, 0.006);
  for (int k = 0; k < 300; ++k) b.step();
  EXPECT_EQ(a.clump_count(), b.clump_count());
  EXPECT_EQ(a.state_hash(), b.state_hash());
  std::filesystem::remove(path);
}

TEST(World, FactoryReportsARegionTooSmall) {
  WorldSettings s = pour(1);
  s.source = "pour.toml";
  s.factories[0].region =
      BoxRegion{Eigen::Vector3d(-0.004, -0.004, 0.005), Eigen::Vector3d(0.004, 0.004, 0.012)};
  s.factories[0].attempts_per_clump = 50;
  try {
    (void)World::create(s);
    FAIL() << "200 pills fitted into 8 x 8 x 7 mm";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "pour.toml");
    EXPECT_EQ(e.field(), "factories[0].region");
    EXPECT_NE(std::string(e.what()).find("could place only"), std::string::npos) << e.what();
  }
  // Smaller than a single clump.
  s.factories[0].region =
      BoxRegion{Eigen::Vector3d(0, 0, 0.01), Eigen::Vector3d(0.002, 0.002, 0.012)};
  EXPECT_THROW((void)World::create(s), InputError);
}

// A box cut by two planes into a V (a hopper's inclined walls): the volume is the closed form's,
// every sphere of every pill lies inside both cuts, the pills reach into the V's lower corner,
// and cuts that leave no room for a pill, or a normal that is not a unit vector, are refused.
TEST(World, FactoryKeepsEveryPillInsideABoxsCuts) {
  const double w = 0.011, h = 0.05, margin = 0.001;
  const Eigen::Vector3d left = Eigen::Vector3d(1, 0, 1).normalized();
  const Eigen::Vector3d right = Eigen::Vector3d(-1, 0, 1).normalized();
  // The V: |x| <= z - 0.005 - √2·margin, cut from the box |x|, |y| <= w, 0.005 <= z <= h.
  BoxRegion v{Eigen::Vector3d(-w, -w, 0.005),
              Eigen::Vector3d(w, w, h),
              {{Eigen::Vector3d(0, 0, 0.005) + margin * left, left},
               {Eigen::Vector3d(0, 0, 0.005) + margin * right, right}}};
  // Closed form: its x-z section is a triangle of height w and base 2w on the tip at
  // z = 0.005 + √2·margin, then a 2w-wide band up to h; the section times the box's 2w in y.
  const double tip = 0.005 + std::sqrt(2.0) * margin;
  const double exact = (w * w + 2 * w * (h - tip - w)) * 2 * w;
  EXPECT_NEAR(region_volume(v), exact, 0.01 * exact);
  EXPECT_NE(describe(v).find("cut by 2 planes"), std::string::npos) << describe(v);

  WorldSettings s = pour(1);
  s.factories[0].region = v;
  s.factories[0].count = 60;
  const World world = World::create(s);
  ASSERT_EQ(world.clump_count(), 60);
  const auto& p = world.sphere_positions();
  const auto& r = world.sphere_radii();
  double lowest = h;
  for (size_t i = 0; i < p.size(); ++i) {
    for (const HalfSpace& c : v.cuts)
      EXPECT_GE((p[i] - c.point).dot(c.normal), r[i] - 1e-12) << "sphere " << i;
    lowest = std::min(lowest, p[i].z());
  }
  // A 1 mm pill's spheres get within a few mm of the V's tip.
  EXPECT_LT(lowest, tip + 0.005);
  for (const auto& x : world.positions()) EXPECT_TRUE(region_contains(v, x));

  // Cuts that leave the box no room for a pill: refused, naming the region.
  s.factories[0].region = BoxRegion{Eigen::Vector3d(-w, -w, 0.005),
                                    Eigen::Vector3d(w, w, h),
                                    {{Eigen::Vector3d(0, 0, h - 0.001), Eigen::Vector3d::UnitZ()}}};
  try {
    (void)World::create(s);
    FAIL() << "a 1 mm slab held a pill";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "factories[0].region");
    EXPECT_NE(std::string(e.what()).find("cut by a plane"), std::string::npos) << e.what();
  }
  s.factories[0].region = BoxRegion{Eigen::Vector3d(-w, -w, 0.005),
                                    Eigen::Vector3d(w, w, h),
                                    {{Eigen::Vector3d(0, 0, 0.01), Eigen::Vector3d(0, 0, 2)}}};
  try {
    (void)World::create(s);
    FAIL() << "a normal of length 2 was taken";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "factories[0].region.cuts[0]");
  }
}

// LIGGGHTS' all_in no: only the centre of mass must lie in the region, so a region not much
// larger than a pill takes several times more pills per batch; walls and other pills are still
// never overlapped.
TEST(World, FactoryPlacesOnlyCentresInTheRegionWhenAsked) {
  auto first_batch = [](bool whole) {
    WorldSettings s = pour(1);
    FactorySettings& f = s.factories[0];
    f.region =
        BoxRegion{Eigen::Vector3d(-0.004, -0.004, 0.02), Eigen::Vector3d(0.004, 0.004, 0.028)};
    f.mixture = {{"A", 1.0}};
    f.count = 1000;
    f.rate = 1000.0;  // clumps/s: the whole count due in the first batch, as many as fit
    f.interval = 1.0;
    f.fail_if_behind = false;
    f.whole_in_region = whole;
    return World::create(s);
  };
  const World whole = first_batch(true), centre = first_batch(false);
  ASSERT_GE(whole.clump_count(), 1);
  EXPECT_GE(centre.clump_count(), 3 * whole.clump_count())
      << whole.clump_count() << " whole, " << centre.clump_count() << " by centre";
  const Eigen::AlignedBox3d region(Eigen::Vector3d(-0.004, -0.004, 0.02),
                                   Eigen::Vector3d(0.004, 0.004, 0.028));
  for (const auto& x : centre.positions()) EXPECT_TRUE(region.contains(x));
  const auto& p = centre.sphere_positions();
  const auto& r = centre.sphere_radii();
  const auto& owner = centre.sphere_clumps();
  int outside = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    outside += !region.contains(p[i]);
    // Spheres of different pills never overlap.
    for (size_t j = i + 1; j < p.size(); ++j) {
      if (owner[i] != owner[j]) {
        EXPECT_GE((p[i] - p[j]).norm(), r[i] + r[j] - 1e-12) << i << " " << j;
      }
    }
  }
  EXPECT_GT(outside, 0);  // pills reach out of the region
  for (const auto& x : whole.sphere_positions()) EXPECT_TRUE(region.contains(x));
}

TEST(World, FactoryMixtureByMassAndRate) {
  WorldSettings s = pour(1);
  FactorySettings& f = s.factories[0];
  f.region =
      BoxRegion{Eigen::Vector3d(-0.011, -0.011, 0.025), Eigen::Vector3d(0.011, 0.011, 0.055)};
  f.velocity = Eigen::Vector3d(0, 0, -0.5);
  f.count.reset();
  const double ma = 4.0 * 4.0 / 3.0 * std::numbers::pi * 1e-9 * 1380.0;  // mass of one pill
  f.mass = 150 * ma;
  f.mixture = {{"A", 0.3}, {"B", 0.7}};
  f.rate = 30 * ma / 0.01;  // 30 pills per 10 ms
  f.interval = 0.01;
  World w = World::create(s);
  EXPECT_EQ(w.clump_count(), 30);  // the first batch at t = 0
  w.run_until(0.06);  // batches at 0, 10, ..., 50 ms; a full region defers pills to the next
  EXPECT_TRUE(w.factories_done());
  EXPECT_NEAR(w.factory_status(0).inserted_mass, 150 * ma, 0.5 * ma);
  double mass_a = 0.0;
  for (int c = 0; c < w.clump_count(); ++c)
    if (w.clump_type_of(c) == 0) mass_a += w.clump_mass(c);
  EXPECT_NEAR(mass_a / w.total_mass(), 0.3, 1.0 / 150);
  // Orientations are random (not all identity).
  int turned = 0;
  for (const auto& q : w.orientations()) turned += std::abs(q.w()) < 0.99;
  EXPECT_GT(turned, 100);
  // Blow-up checks saw energy in balance while pills were added and fell.
  EXPECT_GT(w.kinetic_energy(), 0.0);
}

// end_below: a factory whose region is nearly full ends at the first batch that places less
// than that fraction of its share, instead of trickling on until a batch places nothing. Until
// then it is the same pour, bit for bit.
TEST(World, FactoryEndsWhenItOnlyTrickles) {
  auto make = [](double end_below) {
    WorldSettings s = pour(1);
    FactorySettings& f = s.factories[0];
    f.region =
        BoxRegion{Eigen::Vector3d(-0.011, -0.011, 0.0), Eigen::Vector3d(0.011, 0.011, 0.014)};
    f.count = 100000;  // far more than the region holds
    f.rate = 1000.0;   // clumps/s: 20 due per 20 ms batch
    f.interval = 0.02;
    f.fail_if_behind = false;
    f.end_below = end_below;
    return World::create(s);
  };
  World trickle = make(0.0), cut = make(0.5);
  std::vector<long> per_batch;  // clumps the cut factory placed in each batch
  long before = 0;
  for (int k = 1; k <= 40 && !cut.factories_done(); ++k) {
    cut.run_until(0.02 * k - 1e-4);  // the batch of t = 0.02 (k - 1) s is in
    trickle.run_until(0.02 * k - 1e-4);
    per_batch.push_back(cut.factory_status(0).inserted - before);
    before = cut.factory_status(0).inserted;
    ASSERT_EQ(cut.state_hash(), trickle.state_hash()) << "batch " << k;
  }
  ASSERT_TRUE(cut.factories_done()) << "the region never filled";
  ASSERT_GE(per_batch.size(), 3u);
  EXPECT_EQ(per_batch.front(), 20);                  // an empty region takes the whole share
  EXPECT_LT(per_batch.back(), 10);                   // the batch that ended it trickled
  for (size_t k = 0; k + 1 < per_batch.size(); ++k)  // and none before it did
    EXPECT_GE(per_batch[k], 10) << "batch " << k;
  // Without end_below the same pour goes on placing pills into the gaps.
  EXPECT_FALSE(trickle.factories_done());
  trickle.run_until(cut.time() + 0.2);
  EXPECT_GT(trickle.factory_status(0).inserted, cut.factory_status(0).inserted);
  // A fraction outside [0, 1] names the field.
  WorldSettings bad = pour(1);
  bad.source = "scene.toml";
  bad.factories[0].end_below = 1.5;
  try {
    (void)World::create(bad);
    FAIL() << "end_below 1.5 accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "factories[0].end_below");
  }
}

// A second pour added while running (World::add_factory, the angle-of-repose rig's top-up once
// its tube is full) is the same as a World created with it in its settings: same state, and the
// checkpoints taken after the call load into such a World and run on bit-identically.
TEST(World, FactoryAddedWhileRunningEqualsOneFromCreation) {
  const double t_add = 0.02;
  FactorySettings second;
  second.name = "top-up";
  second.region =
      BoxRegion{Eigen::Vector3d(-0.008, -0.008, 0.04), Eigen::Vector3d(0.008, 0.008, 0.055)};
  second.mixture = {{"B", 1.0}};
  second.count = 40;
  second.rate = 2000.0;               // clumps/s, in batches of the region's free-fall time
  second.start_time = t_add + 0.005;  // after the call: both Worlds run its first batch alike
  second.fail_if_behind = false;
  second.whole_in_region = false;
  WorldSettings first = pour(1);
  first.factories[0].count = 60;
  WorldSettings both = first;
  both.factories.push_back(second);

  World a = World::create(both);
  World b = World::create(first);
  a.run_until(t_add);
  b.run_until(t_add);
  ASSERT_EQ(b.factory_count(), 1);
  b.add_factory(second);
  ASSERT_EQ(b.factory_count(), 2);
  ASSERT_EQ(a.state_hash(), b.state_hash());
  const auto path = std::filesystem::path(CLUMPKIT_BINARY_DIR) / "factory_added_test.ckpt";
  b.run_until(t_add + 0.01);
  b.save_checkpoint(path);
  a.run_until(0.08);
  b.run_until(0.08);
  EXPECT_EQ(a.state_hash(), b.state_hash());
  EXPECT_GT(b.factory_status(1).inserted, 0);
  EXPECT_EQ(b.clump_count(), 60 + b.factory_status(1).inserted);
  // The checkpoint loads into a World created with both factories, not into one with one.
  World c = World::create(both);
  c.load_checkpoint(path);
  c.run_until(0.08);
  EXPECT_EQ(c.state_hash(), b.state_hash());
  World d = World::create(first);
  EXPECT_THROW(d.load_checkpoint(path), InputError);
  std::filesystem::remove(path);
  // A start before now would catch its batches up at once; a bad setting names its index.
  FactorySettings late = second;
  late.start_time = 0.0;
  EXPECT_THROW(b.add_factory(late), InputError);
  FactorySettings unknown = second;
  unknown.start_time = 1.0;
  unknown.mixture = {{"Z", 1.0}};
  try {
    b.add_factory(unknown);
    ADD_FAILURE() << "an unknown clump type was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("factories[2].mixture[0].clump_type"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(b.factory_count(), 2);
}

TEST(World, TimeStepDefaultWarningAndLimit) {
  WorldSettings s;
  const double r = 2e-3;
  s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
  const double tr = rayleigh_time(r, 1380.0, 1.1e8 / 2.7, 0.35);
  World w = World::create(s);
  EXPECT_NEAR(w.dt(), 0.2 * tr, 1e-12 * tr);
  EXPECT_TRUE(w.warnings().empty());
  s.rayleigh_fraction = 0.5;
  World w2 = World::create(s);
  ASSERT_FALSE(w2.warnings().empty());
  EXPECT_NE(w2.warnings()[0].find("Rayleigh"), std::string::npos);
  s.rayleigh_fraction = 0.2;
  s.time_step = 50.0 * tr;
  try {
    (void)World::create(s);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "time_step");
  }
}

TEST(World, BlowUpStopsWithADiagnosis) {
  WorldSettings s;
  s.gravity.setZero();
  const double r = 2e-3;
  s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
  s.walls.push_back(test::floor_wall(0.1, 2));
  {
    World w = World::create(s);
    w.add_clump(0, Eigen::Vector3d(0, 0, 0.2 * r));  // 80 % of the radius inside the floor
    try {
      w.step();
      FAIL();
    } catch (const NumericalError& e) {
      EXPECT_NE(std::string(e.what()).find("wall 'floor'"), std::string::npos) << e.what();
    }
  }
  {
    World w = World::create(s);
    w.add_clump(0, Eigen::Vector3d(0, 0, 0.05), Eigen::Quaterniond::Identity(),
                Eigen::Vector3d(80.0, 0, 0));
    EXPECT_THROW(w.run_until(0.01), NumericalError);
  }
}

}  // namespace
}  // namespace clumpkit::dem

namespace clumpkit::dem {
namespace {

// Removing a clump that never touched the others leaves their evolution bit-identical to a run
// without it, contact histories included.
TEST(World, RemoveClumpsKeepsTheRestBitIdentical) {
  WorldSettings s;
  const double r = 2e-3;
  s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
  s.walls.push_back(test::floor_wall(0.2, 4));
  auto populate = [&](World& w, bool with_far) {
    w.add_clump(0, Eigen::Vector3d(0, 0, r), Eigen::Quaterniond::Identity(),
                Eigen::Vector3d(0.1, 0, 0));
    if (with_far) w.add_clump(0, Eigen::Vector3d(0.05, 0.05, 0.02));
    w.add_clump(0, Eigen::Vector3d(0.004, 0, r + 1e-4));  // hit by the first one
  };
  World a = World::create(s), b = World::create(s);
  populate(a, true);
  populate(b, false);
  for (int k = 0; k < 3000; ++k) a.step(), b.step();
  EXPECT_EQ(a.remove_clumps([](int c) { return c == 1; }), 1);
  ASSERT_EQ(a.clump_count(), 2);
  for (int k = 0; k < 3000; ++k) a.step(), b.step();
  for (int c = 0; c < 2; ++c) {
    EXPECT_EQ(a.positions()[c], b.positions()[c]);
    EXPECT_EQ(a.velocities()[c], b.velocities()[c]);
  }
  EXPECT_EQ(a.remove_clumps([](int) { return true; }), 2);
  a.step();
  EXPECT_EQ(a.sphere_count(), 0);
}

}  // namespace
}  // namespace clumpkit::dem
