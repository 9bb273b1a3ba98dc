// The contact law against closed forms: Hertz force–overlap, contact duration, restitution.
#include <gtest/gtest.h>

#include <cmath>

#include "clumpkit/core/error.hpp"
#include "clumpkit/dem/time_step.hpp"
#include "scenes.hpp"

namespace clumpkit::dem {
namespace {

TEST(ContactLaw, HertzForceOverlapMatchesClosedForm) {
  const Material pill{"pill", 1380.0, 0.35, 1.1e8};
  const Material steel{"steel", 7865.0, 0.3, 7.9e10};
  PairContact law;  // no damping, no friction: pure Hertz
  const ResolvedContact r = resolve(pill, steel, law);
  const double e_star = 1.0 / ((1 - 0.35 * 0.35) / 1.1e8 + (1 - 0.09) / 7.9e10);
  EXPECT_NEAR(r.e_star, e_star, 1e-9 * e_star);
  const double g_star = 1.0 / (2 * (2 - 0.35) * (1 + 0.35) / 1.1e8 + 2 * (2 - 0.3) * 1.3 / 7.9e10);
  EXPECT_NEAR(r.g_star, g_star, 1e-9 * g_star);
  for (double delta : {1e-7, 1e-6, 1e-5, 3e-5}) {
    ContactKinematics k;
    k.normal = Eigen::Vector3d::UnitZ();
    k.overlap = delta;
    k.r_star = 1e-3;
    k.m_star = 1e-4;
    k.v_rel = Eigen::Vector3d(0.1, 0, -0.2);  // ignored without damping and friction
    k.omega_i = k.omega_j = Eigen::Vector3d::Zero();
    ContactHistory h;
    ContactForce f;
    evaluate_contact(r, k, 1e-6, h, f);
    const double expected = 4.0 / 3.0 * e_star * std::sqrt(1e-3) * std::pow(delta, 1.5);
    EXPECT_NEAR(f.force.z(), expected, 1e-12 * expected);
    EXPECT_EQ(f.force.x(), 0.0);
    EXPECT_NEAR(f.elastic_energy, 8.0 / 15.0 * e_star * std::sqrt(1e-3) * std::pow(delta, 2.5),
                1e-12 * expected * delta);
  }
}

TEST(ContactLaw, CoulombCapRescalesTheSpring) {
  const Material pill{"pill", 1380.0, 0.35, 1.1e8};
  PairContact law;
  law.static_friction = 0.4;
  const ResolvedContact r = resolve(pill, pill, law);
  ContactKinematics k;
  k.normal = Eigen::Vector3d::UnitZ();
  k.overlap = 1e-5;
  k.r_star = 1e-3;
  k.m_star = 1e-4;
  k.v_rel = Eigen::Vector3d(1.0, 0, 0);  // large slip
  k.omega_i = k.omega_j = Eigen::Vector3d::Zero();
  ContactHistory h;
  ContactForce f;
  evaluate_contact(r, k, 1e-4, h, f);
  EXPECT_NEAR(std::abs(f.force.x()), 0.4 * f.force.z(), 1e-12 * f.force.z());
  EXPECT_LT(f.force.x(), 0.0);  // opposes the slip
  const double st = 8.0 * r.g_star * std::sqrt(1e-3 * 1e-5);
  EXPECT_NEAR(h.shear.x() * st, -f.force.x(), 1e-9 * std::abs(f.force.x()));
}

TEST(ContactLaw, AbsentEffectsAreNotEvaluated) {
  const Material pill{"pill", 1380.0, 0.35, 1.1e8};
  PairContact law;
  law.rolling = RollingFriction{RollingModel::kStandard, 0.0, 0.3};
  const ResolvedContact present = resolve(pill, pill, law);
  EXPECT_TRUE(present.rolling);
  EXPECT_FALSE(present.friction);
  EXPECT_FALSE(present.damping);
  EXPECT_FALSE(present.cohesion);
  // Cohesion pulls the spheres together by k 2π R* δ.
  law.cohesion = Cohesion{1e5};
  const ResolvedContact coh = resolve(pill, pill, law);
  ContactKinematics k;
  k.normal = Eigen::Vector3d::UnitZ();
  k.overlap = 1e-6;
  k.r_star = 1e-3;
  k.m_star = 1e-4;
  k.v_rel.setZero();
  k.omega_i = k.omega_j = Eigen::Vector3d::Zero();
  ContactHistory h;
  ContactForce a, b;
  evaluate_contact(present, k, 1e-6, h, a);
  evaluate_contact(coh, k, 1e-6, h, b);
  EXPECT_NEAR(a.force.z() - b.force.z(), 1e5 * 2.0 * std::numbers::pi * 1e-3 * 1e-6, 1e-15);
}

TEST(ContactLaw, BadValuesAreInputErrors) {
  for (double e : {0.0, -0.1, 1.2}) {
    PairContact law;
    law.restitution = e;
    EXPECT_THROW(law.validate("scene.toml", "pair"), InputError) << e;
  }
  PairContact ok;
  ok.restitution = 1.0;
  EXPECT_NO_THROW(ok.validate("scene.toml", "pair"));

  WorldSettings s;
  s.clump_types.push_back(test::sphere_type("ball", 2e-3, 1380.0));
  MaterialLibrary lib = MaterialLibrary::paper_table1();
  lib.add({"pill", -1380.0, 0.35, 1.1e8});
  s.materials = lib;
  try {
    (void)World::create(s);
    FAIL() << "negative density accepted";
  } catch (const InputError& err) {
    EXPECT_EQ(err.field(), "materials.pill.density");
  }
  lib.add({"pill", 1380.0, 0.35, -1.0});
  s.materials = lib;
  EXPECT_THROW((void)World::create(s), InputError);
  lib.add({"pill", 1380.0, 0.35, 1.1e8});
  lib.set_interaction("pill", "pill", {1.5, 0.5, 0.1});
  s.materials = lib;
  EXPECT_THROW((void)World::create(s), InputError);
}

// Two equal spheres meet head-on without gravity; returns (restitution, contact duration).
// rayleigh_fraction 0 = the default time step (0.2 T_R).
std::pair<double, double> head_on(double e, double speed, bool with_wall,
                                  double rayleigh_fraction = 0.02, double gap = 1e-5) {
  WorldSettings s;
  s.gravity.setZero();
  s.materials = test::test_materials(e, 0.5, 0.0);
  const double r = 3e-3;
  s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
  if (with_wall) s.walls.push_back(test::floor_wall(0.05, 4));
  s.max_impact_speed = speed;
  if (rayleigh_fraction > 0.0)
    s.time_step = rayleigh_fraction * rayleigh_time(r, 1380.0, 1.1e8 / 2.7, 0.35);
  World w = World::create(s);
  if (with_wall) {
    w.add_clump(0, Eigen::Vector3d(0, 0, r + gap), Eigen::Quaterniond::Identity(),
                Eigen::Vector3d(0, 0, -speed));
  } else {
    w.add_clump(0, Eigen::Vector3d(0, 0, -r - gap), Eigen::Quaterniond::Identity(),
                Eigen::Vector3d(0, 0, speed / 2));
    w.add_clump(0, Eigen::Vector3d(0, 0, r + gap), Eigen::Quaterniond::Identity(),
                Eigen::Vector3d(0, 0, -speed / 2));
  }
  double t_on = -1.0, t_off = -1.0;
  for (int k = 0; k < 200000 && t_off < 0.0; ++k) {
    w.step();
    const bool touching = w.contact_count() > 0;
    if (touching && t_on < 0.0) t_on = w.time();
    if (!touching && t_on >= 0.0) t_off = w.time();
  }
  const double v_out =
      with_wall ? w.velocities()[0].z() : w.velocities()[1].z() - w.velocities()[0].z();
  return {v_out / speed, t_off - t_on};
}

TEST(ContactLaw, ContactDurationMatchesHertz) {
  const double r = 3e-3, speed = 0.5;
  const double m = 4.0 / 3.0 * std::numbers::pi * r * r * r * 1380.0;
  const Material pill{"pill", 1380.0, 0.35, 1.1e8};
  const Material steel{"galvanized_steel", 7865.0, 0.3, 7.9e10};
  const auto [e_pp, t_pp] = head_on(1.0, speed, false);
  const double tc_pp = hertz_contact_time(resolve(pill, pill, {}).e_star, r / 2, m / 2, speed);
  EXPECT_NEAR(t_pp, tc_pp, 0.01 * tc_pp);
  EXPECT_NEAR(e_pp, 1.0, 1e-3);
  const auto [e_pw, t_pw] = head_on(1.0, speed, true);
  const double tc_pw = hertz_contact_time(resolve(pill, steel, {}).e_star, r, m, speed);
  EXPECT_NEAR(t_pw, tc_pw, 0.01 * tc_pw);
  EXPECT_NEAR(e_pw, 1.0, 1e-3);
}

class Restitution : public ::testing::TestWithParam<double> {};

// At the default time step (0.2 T_R, 15-25 steps per contact here), for impact speeds from 0.1 to
// 2 m/s and for several phases of the first touch between two steps (the start and end of a
// contact fall anywhere inside a step; the damping impulse must not depend on where).
TEST_P(Restitution, HeadOnSphereSphereAndSphereWall) {
  const double e = GetParam();
  for (double speed : {0.1, 0.5, 2.0})
    for (double gap : {1e-6, 1.3e-5, 3.7e-5}) {
      SCOPED_TRACE(::testing::Message() << "speed " << speed << " m/s, gap " << gap << " m");
      EXPECT_NEAR(head_on(e, speed, false, 0.0, gap).first, e, 0.02 * e);
      EXPECT_NEAR(head_on(e, speed, true, 0.0, gap).first, e, 0.02 * e);
    }
}

INSTANTIATE_TEST_SUITE_P(DEM, Restitution, ::testing::Values(0.2, 0.3, 0.5, 0.7, 0.9));

}  // namespace
}  // namespace clumpkit::dem

namespace clumpkit::dem {
namespace {

// Cohesion as a World effect: two spheres pressed together stay together with SJKR and part
// without it (all else equal and elastic).
TEST(ContactLaw, CohesionHoldsSpheresTogether) {
  auto final_gap = [](bool cohesive) {
    WorldSettings s;
    s.gravity.setZero();
    PairContact law;
    law.restitution = 0.3;
    if (cohesive) law.cohesion = Cohesion{2e6};
    s.pair_contacts.push_back({"pill", "pill", law});
    const double r = 1e-3;
    s.clump_types.push_back(test::sphere_type("ball", r, 1380.0));
    World w = World::create(s);
    w.add_clump(0, Eigen::Vector3d(-r, 0, 0), Eigen::Quaterniond::Identity(),
                Eigen::Vector3d(0.02, 0, 0));
    w.add_clump(0, Eigen::Vector3d(r, 0, 0), Eigen::Quaterniond::Identity(),
                Eigen::Vector3d(-0.02, 0, 0));
    w.run_until(0.005);
    return (w.positions()[1] - w.positions()[0]).norm() - 2.0 * r;
  };
  EXPECT_LT(final_gap(true), 0.0);
  EXPECT_GT(final_gap(false), 1e-5);
}

}  // namespace
}  // namespace clumpkit::dem
