#include "clumpkit/calibrate/measurements.hpp"

#include <gtest/gtest.h>

#include "clumpkit/core/error.hpp"

using namespace clumpkit;

namespace {
const std::string kHeader = "rig,sample,setting,quantity,value,std,n,unit\n";
std::string error_of(const std::string& body) {
  try {
    parse_measurements(kHeader + body, "m.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Measurements, ReadsTheSpecFormat) {
  const auto m =
      parse_measurements("# lab, March\n" + kHeader +
                             "bulk_density,A,,bulk_density,712.4,6.1,3,kg/m^3\n"
                             "angle_of_repose,mix,plate=galvanized_steel,angle,27.3,0.8,3,deg\n"
                             "\n"
                             "discharge,mix,rpm=15,pocket_mass,240,5,3,g\n"
                             "discharge,mix,rpm=30,pocket_mass_cv,0.04,0.01,3,1\n",
                         "m.csv");
  ASSERT_EQ(m.size(), 4u);
  EXPECT_EQ(m[0].line, 3);
  EXPECT_DOUBLE_EQ(m[0].value, 712.4);
  EXPECT_EQ(m[1].setting.at("plate"), "galvanized_steel");
  EXPECT_NEAR(m[2].value, 0.240, 1e-15);  // g converted to the canonical kg
  EXPECT_NEAR(m[2].std, 0.005, 1e-15);
  EXPECT_EQ(m[2].unit, "kg");
  EXPECT_EQ(m[3].n, 3);
}

// A spreadsheet's spellings of the units: converted to the canonical unit like any other.
TEST(Measurements, SpreadsheetUnitSpellings) {
  const auto m =
      parse_measurements(kHeader +
                             "bulk_density,A,,bulk_density,712.4,6.1,3,g/L\n"
                             "angle_of_repose,mix,plate=galvanized_steel,angle,27.3,0.8,3,\u00b0\n"
                             "discharge,mix,rpm=15,mass_flow,1260,36,3,kg/h\n"
                             "discharge,mix,rpm=30,pocket_mass_cv,4,1,3,%\n",
                         "m.csv");
  ASSERT_EQ(m.size(), 4u);
  EXPECT_DOUBLE_EQ(m[0].value, 712.4);
  EXPECT_EQ(m[0].unit, "kg/m^3");
  EXPECT_DOUBLE_EQ(m[1].value, 27.3);
  EXPECT_EQ(m[1].unit, "deg");
  EXPECT_NEAR(m[2].value, 0.35, 1e-15);
  EXPECT_NEAR(m[2].std, 0.01, 1e-15);
  EXPECT_EQ(m[2].unit, "kg/s");
  EXPECT_NEAR(m[3].value, 0.04, 1e-15);
  EXPECT_NEAR(m[3].std, 0.01, 1e-15);
}

TEST(Measurements, ColumnsInAnyOrderAndExtraColumns) {
  const auto m = parse_measurements(
      "note,unit,n,std,value,quantity,setting,sample,rig\n"
      "x,deg,3,1.0,25,angle,,A,angle_of_repose\n",
      "m.csv");
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].rig, "angle_of_repose");
}

// Every bad line names the file, the line and the column.
TEST(Measurements, BadLinesAreNamed) {
  struct Case {
    std::string body, needle;
  };
  const Case cases[] = {
      {"heap,A,,angle,25,1,3,deg\n", "m.csv:2: rig: unknown rig 'heap'"},
      {"angle_of_repose,D,,angle,25,1,3,deg\n", "m.csv:2: sample: unknown sample 'D'"},
      {"angle_of_repose,A,,slope,25,1,3,deg\n",
       "m.csv:2: quantity: rig 'angle_of_repose' does not"},
      {"angle_of_repose,A,rpm=10,angle,25,1,3,deg\n",
       "m.csv:2: setting: rig 'angle_of_repose' has no setting 'rpm'"},
      {"discharge,mix,rpm=fast,pocket_mass,0.25,0.01,3,kg\n",
       "m.csv:2: setting: setting rpm='fast'"},
      {"angle_of_repose,A,,angle,25,1,3,kg\n", "m.csv:2: unit: unit 'kg' is not a unit of angle"},
      {"angle_of_repose,A,,angle,25,,3,deg\n", "m.csv:2: std: missing"},
      {"angle_of_repose,A,,angle,25,-1,3,deg\n", "m.csv:2: std: must be positive"},
      {"angle_of_repose,A,,angle,25,0,3,deg\n", "m.csv:2: std: must be positive"},
      {"angle_of_repose,A,,angle,25,1,0,deg\n", "m.csv:2: n: must be a whole number"},
      {"angle_of_repose,A,,angle,25,1,2.5,deg\n", "m.csv:2: n: must be a whole number"},
      {"angle_of_repose,A,,angle,abc,1,3,deg\n", "m.csv:2: value: 'abc' is not a number"},
      {"angle_of_repose,A,,angle,nan,1,3,deg\n", "m.csv:2: value: 'nan' is not finite"},
      {"bulk_density,A,,bulk_density,-700,1,3,kg/m^3\n", "m.csv:2: value: must not be negative"},
      {"angle_of_repose,A,,angle,25,1,3,deg\nangle_of_repose,A,,angle,26,1,3,deg\n",
       "m.csv:3: duplicate of line 2"},
      {"discharge,mix,rpm=15,pocket_mass,1,1,3,kg\ndischarge,mix,rpm=15.0,pocket_mass,1,1,3,kg\n",
       "m.csv:3: duplicate of line 2"},
      {"angle_of_repose,A,\"plate=abs_plastic,angle,25,1,3,deg\n", "m.csv:2: unterminated quote"},
      {"", "m.csv: no measurements"},
  };
  for (const Case& c : cases) {
    const std::string e = error_of(c.body);
    EXPECT_NE(e.find(c.needle), std::string::npos) << "line: " << c.body << "got: " << e;
  }
  try {
    parse_measurements("rig,sample,quantity,value,std,n,unit\n", "h.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("h.csv:1: setting: missing column"), std::string::npos);
  }
  EXPECT_THROW(parse_measurements("", "e.csv"), InputError);
  // A semicolon-separated export is named as such, not as a missing column.
  try {
    parse_measurements("rig;sample;setting;quantity;value;std;n;unit\n", "s.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s.csv:1: the header is separated by ';'"),
              std::string::npos)
        << e.what();
  }
}

TEST(Measurements, FormatRoundTrips) {
  const auto m =
      parse_measurements(kHeader +
                             "discharge,mix,rpm=15,pocket_mass,0.24,0.005,3,kg\n"
                             "angle_of_repose,C,plate=abs_plastic,angle_left,26.1,0.9,3,deg\n",
                         "m.csv");
  const auto r = parse_measurements(format_measurements(m), "r.csv");
  ASSERT_EQ(r.size(), m.size());
  for (size_t i = 0; i < m.size(); ++i) {
    EXPECT_EQ(r[i].key(), m[i].key());
    EXPECT_DOUBLE_EQ(r[i].value, m[i].value);
    EXPECT_DOUBLE_EQ(r[i].std, m[i].std);
  }
}

TEST(Measurements, OneMeasurementGivenTwiceIsNamedByItsLines) {
  // mass_flow is pocket_mass x 8 x rpm / 60 in every run, angle the mean of the two flanks: a
  // file with both counts one measurement twice; the pairs are named, independent rows are not.
  const auto m = parse_measurements(kHeader +
                                        "discharge,A,rpm=15,pocket_mass,0.17,0.01,3,kg\n"
                                        "discharge,A,rpm=30,mass_flow,0.6,0.02,3,kg/s\n"
                                        "discharge,A,rpm=15,mass_flow,0.34,0.02,3,kg/s\n"
                                        "discharge,A,rpm=15,pocket_mass_cv,0.05,0.01,3,1\n"
                                        "angle_of_repose,A,,angle_left,30,1,3,deg\n"
                                        "angle_of_repose,A,,angle,30,1,3,deg\n"
                                        "angle_of_repose,B,,angle,30,1,3,deg\n"
                                        "bulk_density,A,,bulk_density,700,10,3,kg/m^3\n",
                                    "lab.csv");
  const std::vector<std::string> w = redundancy_warnings(m, "lab.csv");
  ASSERT_EQ(w.size(), 2u);
  EXPECT_NE(w[0].find("lab.csv:2 (pocket_mass) and line 4 (mass_flow), discharge rpm=15"),
            std::string::npos)
      << w[0];
  EXPECT_NE(w[1].find("lab.csv:6 (angle_left) and line 7 (angle), angle_of_repose:"),
            std::string::npos)
      << w[1];
  EXPECT_NE(w[0].find("counts this measurement twice"), std::string::npos);
  EXPECT_TRUE(
      redundancy_warnings(std::vector<Measurement>(m.begin() + 1, m.begin() + 2), "x").empty());
}
