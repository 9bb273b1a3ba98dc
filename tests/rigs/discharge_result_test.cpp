// The discharger's observables from the counted pockets' fills, and the jam flag (procedure.hpp).
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "clumpkit/core/error.hpp"
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

// A stand-in for one discharge: the wheel jams for the seeds in `jams`, else flows.
RepeatResult fake_discharge(const Ctx& c, const std::vector<std::uint64_t>& jams,
                            std::vector<std::uint64_t>& seeds, std::vector<std::string>& dirs) {
  seeds.push_back(c.seed);
  dirs.push_back(c.dir.filename().string());
  const bool jam = std::find(jams.begin(), jams.end(), c.seed) != jams.end();
  RepeatResult r;
  r.values["pocket_mass"] = jam ? 0.0 : 0.17;
  r.details["jam"] = jam ? nlohmann::json("no counted pocket received a pill") : nlohmann::json();
  return r;
}

// A jammed wheel is run again from a fresh fill with another seed, in its own folder, as a lab
// clears the rig; the result says which attempts jammed and which seed flowed.
TEST(DischargeJam, AJammedRepeatIsRunAgainWithAnotherSeed) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("clumpkit_jam_retry_test_" + std::to_string(::getpid())) /
                                    "repeat_1";
  std::filesystem::remove_all(dir.parent_path());
  std::filesystem::create_directories(dir);
  RigRequest req;
  std::vector<std::string> said;
  req.progress = [&](const std::string& s) { said.push_back(s); };
  Ctx c{req, rig_scale("discharge", {{"scale", "tiny"}}), {}, dir, 7, 0};
  std::vector<std::uint64_t> seeds;
  std::vector<std::string> dirs;
  const RepeatResult r =
      run_attempts(c, [&](Ctx& a) { return fake_discharge(a, {7}, seeds, dirs); });
  EXPECT_EQ(seeds, (std::vector<std::uint64_t>{7, 7 + kJamSeedStep}));
  EXPECT_EQ(dirs, (std::vector<std::string>{"repeat_1", "retry_1"}));
  EXPECT_TRUE(std::filesystem::is_directory(dir / "retry_1"));
  EXPECT_DOUBLE_EQ(r.values.at("pocket_mass"), 0.17);
  ASSERT_EQ(r.details.at("jammed").size(), 1u);
  EXPECT_EQ(r.details.at("jammed")[0].at("seed"), 7u);
  EXPECT_EQ(r.details.at("seed_used"), 7u + kJamSeedStep);
  ASSERT_EQ(said.size(), 1u);
  EXPECT_NE(said[0].find("running again from a fresh fill with seed 1007"), std::string::npos)
      << said[0];

  // A wheel that flows at once: one attempt, no record of retries.
  seeds.clear();
  dirs.clear();
  const RepeatResult fine =
      run_attempts(c, [&](Ctx& a) { return fake_discharge(a, {}, seeds, dirs); });
  EXPECT_EQ(seeds.size(), 1u);
  EXPECT_FALSE(fine.details.contains("jammed"));
  std::filesystem::remove_all(dir.parent_path());
}

// Every attempt jammed: the repeat fails, naming the seeds; with --bed-from nothing is retried.
TEST(DischargeJam, EveryAttemptJammedIsAFailure) {
  RigRequest req;
  Ctx c{req, rig_scale("discharge", {{"scale", "tiny"}}), {}, {}, 1, 0};
  std::vector<std::uint64_t> seeds;
  std::vector<std::string> dirs;
  const std::vector<std::uint64_t> all = {1, 1 + kJamSeedStep, 1 + 2 * kJamSeedStep};
  try {
    run_attempts(c, [&](Ctx& a) { return fake_discharge(a, all, seeds, dirs); });
    FAIL() << "no error";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("jammed in all 3 attempts (seeds 1, 1001, 2001)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(seeds, all);
  EXPECT_EQ(kJamAttempts, 3);

  req.bed_from = "earlier_run";
  seeds.clear();
  const RepeatResult kept =
      run_attempts(c, [&](Ctx& a) { return fake_discharge(a, all, seeds, dirs); });
  EXPECT_EQ(seeds.size(), 1u);
  EXPECT_TRUE(kept.details.at("jam").is_string());
  EXPECT_EQ(kept.details.at("jammed").size(), 1u);
}

}  // namespace
}  // namespace clumpkit::rigs::detail
