// The scales' parameters (rig_scale): what each scale asks of a rig, and the settings that
// override them.
#include <gtest/gtest.h>

#include "clumpkit/core/error.hpp"
#include "clumpkit/rigs/rig.hpp"

namespace clumpkit::rigs {
namespace {

TEST(RigScale, PaperDischargeIsASliceHoldingTheBedPerLengthOfThePaper) {
  // Paper scale: small's 20 mm slice of the full-size wheel at Table 1's stiffness, holding the
  // paper's 10 kg per 100 mm of pocket, filled at 1 kg/s per 20 mm.
  const ScaleParams p = rig_scale("discharge", {{"scale", "paper"}});
  EXPECT_EQ(p.name, "paper");
  EXPECT_DOUBLE_EQ(p.stiffness_scale, 1.0);
  EXPECT_DOUBLE_EQ(p.wheel_scale, 1.0);
  EXPECT_DOUBLE_EQ(p.slice_length, 0.020);
  EXPECT_NEAR(p.bed_mass, 2.0, 1e-12);
  EXPECT_NEAR(p.pour_rate, 1.0, 1e-12);
  EXPECT_EQ(p.pockets_measured, 8);
  // The whole 100 mm pocket: the paper's 10 kg, five times the rate.
  const ScaleParams full = rig_scale("discharge", {{"scale", "paper"}, {"slice", "100"}});
  EXPECT_NEAR(full.slice_length, 0.100, 1e-15);
  EXPECT_NEAR(full.bed_mass, 10.0, 1e-12);
  EXPECT_NEAR(full.pour_rate, 5.0, 1e-12);
  // The bed per length is the paper's at any slice.
  const ScaleParams thin = rig_scale("discharge", {{"scale", "paper"}, {"slice", "30"}});
  EXPECT_NEAR(thin.bed_mass / thin.slice_length, kPaperBedPerLength, 1e-9);
}

TEST(RigScale, TheOtherRigsAndScalesKeepTheirParameters) {
  // The paper's slow D 20 mm pour stays with the cup and the tube.
  for (const char* rig : {"bulk_density", "angle_of_repose"}) {
    const ScaleParams p = rig_scale(rig, {{"scale", "paper"}});
    EXPECT_DOUBLE_EQ(p.pour_rate, 0.04) << rig;
    EXPECT_DOUBLE_EQ(p.heap_mass, 0.5) << rig;
  }
  // small and mini discharge beds do not follow the slice.
  const ScaleParams small = rig_scale("discharge", {{"scale", "small"}, {"slice", "30"}});
  EXPECT_DOUBLE_EQ(small.bed_mass, 0.4);
  EXPECT_DOUBLE_EQ(small.pour_rate, 0.3);
  const ScaleParams mini = rig_scale("discharge", {{"scale", "mini"}});
  EXPECT_DOUBLE_EQ(mini.slice_length, 0.024);
  EXPECT_DOUBLE_EQ(mini.bed_mass, 0.08);
}

TEST(RigScale, TimeStepFractionByScaleAndBySetting) {
  // 0.3 of the Rayleigh time at tiny and mini, 0.25 at small, 0.2 at paper.
  const std::pair<const char*, double> by_scale[] = {
      {"tiny", 0.3}, {"mini", 0.3}, {"small", 0.25}, {"paper", 0.2}};
  for (const auto& [scale, fraction] : by_scale)
    for (const char* rig : {"bulk_density", "angle_of_repose", "discharge"})
      EXPECT_DOUBLE_EQ(rig_scale(rig, {{"scale", scale}}).rayleigh_fraction, fraction)
          << rig << " " << scale;
  // --set rayleigh_fraction=F overrides it, within (0, 0.4].
  EXPECT_DOUBLE_EQ(rig_scale("angle_of_repose", {{"scale", "paper"}, {"rayleigh_fraction", "0.25"}})
                       .rayleigh_fraction,
                   0.25);
  for (const char* bad : {"0", "-0.1", "0.41", "nan"}) {
    try {
      rig_scale("bulk_density", {{"rayleigh_fraction", bad}});
      ADD_FAILURE() << bad << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("rayleigh_fraction"), std::string::npos) << e.what();
    }
  }
}

TEST(RigScale, AnUnknownRigIsNamed) {
  try {
    rig_scale("hopper", {{"scale", "paper"}});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("hopper"), std::string::npos) << e.what();
  }
}

// Cached rig runs key on their rig's revision, so that a change to one rig keeps the other rigs'
// cached runs. The heap and the cup are still at the revision the shared counter had reached (3),
// so their caches made before session 40 keep their keys; the discharger moved on alone, to 4
// (session 41: its pour region cut by the hopper's walls) and 5 (session 42: a jam retried).
TEST(RigRevision, EachRigHasItsOwn) {
  EXPECT_EQ(rig_revision("bulk_density"), 3);
  EXPECT_EQ(rig_revision("angle_of_repose"), 3);
  EXPECT_EQ(rig_revision("discharge"), 5);
  EXPECT_EQ(rig_revision("discharge"), kDischargeRevision);
}

}  // namespace
}  // namespace clumpkit::rigs
