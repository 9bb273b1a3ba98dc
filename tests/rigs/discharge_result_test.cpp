// The discharger's observables from the counted pockets' fills, and the jam flag (procedure.hpp).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "clumpkit/rigs/geometry.hpp"
#include "clumpkit/rigs/rig.hpp"
#include "rigs/procedure.hpp"

namespace clumpkit::rigs::detail {
namespace {

// A session-40 bench run at mini (softened pills, 15 rpm, seed 2) whose wheel jammed: its three
// counted pockets closed with 9.75, 0.65 and 0 g in the slice (CV 1.57).
TEST(DischargeJam, PocketsThatStarveAreNamed) {
  const nlohmann::json j = discharge_jam({9.7526e-3, 0.6502e-3, 0.0});
  ASSERT_TRUE(j.is_string());
  const std::string s = j.get<std::string>();
  EXPECT_NE(s.find("pockets 2, 3 closed"), std::string::npos) << s;
  EXPECT_NE(s.find("0.009753 kg"), std::string::npos) << s;
  EXPECT_NE(s.find("arch over the throat"), std::string::npos) << s;
  const nlohmann::json one = discharge_jam({6.0e-3, 1.4e-3, 6.2e-3});
  ASSERT_TRUE(one.is_string());
  EXPECT_NE(one.get<std::string>().find("pocket 2 closed"), std::string::npos);
}

// A wheel whose counted pockets all closed empty never received the flow.
TEST(DischargeJam, AnEmptyWheelIsOne) {
  for (const std::vector<double>& fills : {std::vector<double>{0.0, 0.0, 0.0}, {0.0}}) {
    const nlohmann::json j = discharge_jam(fills);
    ASSERT_TRUE(j.is_string());
    EXPECT_NE(j.get<std::string>().find("no counted pocket received a pill"), std::string::npos);
  }
}

// Ordinary runs: tiny's three seeds at 15 rpm (6.19 / 6.33 / 5.76 g ...) and mini's pocket
// scatter of ~5-10 % are not jams; neither is one pocket with pills, nor no pocket counted.
TEST(DischargeJam, OrdinaryFillsAreNot) {
  EXPECT_TRUE(discharge_jam({6.19e-3, 6.33e-3, 5.76e-3}).is_null());
  EXPECT_TRUE(discharge_jam({5.53e-3, 6.00e-3, 5.03e-3}).is_null());
  EXPECT_TRUE(discharge_jam({0.0108, 0.0101, 0.0095, 0.0112, 0.0104}).is_null());
  EXPECT_TRUE(discharge_jam({0.010, 0.0026}).is_null());  // just over a quarter
  EXPECT_TRUE(discharge_jam({0.010}).is_null());
  EXPECT_TRUE(discharge_jam({}).is_null());
}

// The result carries the flag beside the observables, which stand as measured.
TEST(DischargeJam, TheResultCarriesIt) {
  const ScaleParams p = rig_scale("discharge", {{"scale", "mini"}, {"rpm", "15"}});
  WheelGeometry g;
  g.length = p.slice_length;
  const RepeatResult jammed = discharge_result(p, g, {9.7526e-3, 0.6502e-3, 0.0}, {}, {});
  EXPECT_TRUE(jammed.details.at("jam").is_string());
  EXPECT_NEAR(jammed.values.at("pocket_mass_cv"), 1.57, 0.01);
  const RepeatResult fine = discharge_result(p, g, {0.0108, 0.0101, 0.0095}, {}, {});
  EXPECT_TRUE(fine.details.at("jam").is_null());
}

}  // namespace
}  // namespace clumpkit::rigs::detail
