#include "clumpkit/sim/scene.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/sim/runner.hpp"

using namespace clumpkit;
namespace fs = std::filesystem;

namespace {
const fs::path kData = CLUMPKIT_SOURCE_DIR;

fs::path temp_dir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("clumpkit_sim_" + name + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string error_of(const std::string& scene_text) {
  const fs::path d = temp_dir("err");
  write_file_atomic(d / "s.toml", scene_text);
  std::string message;
  try {
    sim::Scene s = sim::load_scene(d / "s.toml", kData);
    auto w = dem::World::create(s.world);
    (void)w;
  } catch (const InputError& e) {
    message = e.what();
  }
  fs::remove_all(d);
  return message;
}

const std::string kBase = R"(
[simulation]
until = "0.01 s"
[[clumps]]
name = "B12"
shape = "pill_B"
spheres = 12
)";
}  // namespace

TEST(Scene, ExampleLoads) {
  const sim::Scene s = sim::load_scene(kData / "examples/pour_cup.toml", kData);
  EXPECT_DOUBLE_EQ(s.until, 0.6);
  ASSERT_EQ(s.world.clump_types.size(), 1u);
  EXPECT_EQ(s.world.clump_types[0].clump.spheres.size(), 12u);
  ASSERT_EQ(s.world.walls.size(), 1u);
  EXPECT_EQ(s.world.walls[0].material, "organic_glass");
  ASSERT_EQ(s.world.factories.size(), 1u);
  EXPECT_EQ(*s.world.factories[0].count, 300);
  EXPECT_NEAR(s.world.gravity.z(), -9.81, 1e-12);
  ASSERT_EQ(s.regions.size(), 1u);
}

TEST(Scene, BadScenesNameFileAndField) {
  struct Case {
    std::string text, needle;
  };
  const Case cases[] = {
      {"[simulation]\n", "simulation.until: missing"},
      {kBase + "[[walls]]\nname = \"w\"\nmaterial = \"steel\"\nprimitive = \"box\"\n"
               "min = \"0 0 0 mm\"\nmax = \"1 1 1 mm\"\n",
       "unknown material 'steel'"},
      {kBase + "[[walls]]\nname = \"w\"\nmaterial = \"abs_plastic\"\nprimitive = \"sphere\"\n",
       "walls.0.primitive: unknown primitive 'sphere'"},
      {kBase + "[[walls]]\nname = \"w\"\nmaterial = \"abs_plastic\"\nmesh = \"nope.stl\"\n",
       "nope.stl"},
      {kBase +
           "[[factories]]\nregion = { kind = \"box\", min = \"0 0 0 mm\", max = \"9 9 9 mm\" }\n"
           "count = 3\nmass = \"1 kg\"\nmixture = [{ clump = \"B12\" }]\n",
       "factories.0: give exactly one of 'count' and 'mass'"},
      {kBase +
           "[[factories]]\nregion = { kind = \"box\", min = \"0 0 0 mm\", max = \"9 9 9 mm\" }\n"
           "count = 3\nmixture = [{ clump = \"B13\" }]\n",
       "B13"},
      {"[simulation]\nuntil = \"0.1 s\"\n[[clumps]]\nname = \"x\"\nshape = \"pill_A\"\nspheres = "
       "7\n",
       "clumps.0.spheres"},
      {"[simulation]\nuntil = \"-1 s\"\n", "simulation.until: value -1 is outside"},
      {kBase + "[simulation.x]\n", ""},
  };
  for (const Case& c : cases) {
    if (c.needle.empty()) continue;
    const std::string e = error_of(c.text);
    EXPECT_NE(e.find(c.needle), std::string::npos) << "scene:\n" << c.text << "\ngot: " << e;
    EXPECT_NE(e.find("s.toml"), std::string::npos) << e;
  }
}

// A box region cut by a plane: the cut is read with its units and its normal made unit, and a
// zero normal is named.
TEST(Scene, ABoxRegionMayBeCutByPlanes) {
  const fs::path d = temp_dir("cut");
  write_file_atomic(d / "s.toml",
                    kBase +
                        "[[factories]]\nregion = { kind = \"box\", min = \"-9 -9 0 mm\", max = "
                        "\"9 9 30 mm\", cuts = [{ point = \"0 0 5 mm\", normal = \"1 0 1\" }] }\n"
                        "count = 3\nmixture = [{ clump = \"B12\" }]\n");
  const sim::Scene s = sim::load_scene(d / "s.toml", kData);
  fs::remove_all(d);
  ASSERT_EQ(s.world.factories.size(), 1u);
  const auto& b = std::get<dem::BoxRegion>(s.world.factories[0].region);
  ASSERT_EQ(b.cuts.size(), 1u);
  EXPECT_NEAR(b.cuts[0].point.z(), 0.005, 1e-15);
  EXPECT_NEAR(b.cuts[0].normal.x(), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(b.cuts[0].normal.norm(), 1.0, 1e-15);
  const std::string e =
      error_of(kBase +
               "[[factories]]\nregion = { kind = \"box\", min = \"-9 -9 0 mm\", max = \"9 9 30 "
               "mm\", cuts = [{ point = \"0 0 5 mm\", normal = \"0 0 0\" }] }\n"
               "count = 3\nmixture = [{ clump = \"B12\" }]\n");
  EXPECT_NE(e.find("factories.0.region.cuts.0.normal: must not be zero"), std::string::npos) << e;
  // Every placement tried tests every cut: more than 16 are refused.
  std::string many;
  for (int k = 0; k < 17; ++k)
    many += std::string(k ? ", " : "") + "{ point = \"0 0 1 mm\", normal = \"0 0 1\" }";
  const std::string e17 = error_of(kBase +
                                   "[[factories]]\nregion = { kind = \"box\", min = \"-9 -9 0 "
                                   "mm\", max = \"9 9 30 mm\", cuts = [" +
                                   many + "] }\ncount = 3\nmixture = [{ clump = \"B12\" }]\n");
  EXPECT_NE(e17.find("factories.0.region.cuts: 17 planes; at most 16"), std::string::npos) << e17;
}

TEST(Runner, WritesSeriesVtkAndFinishedState) {
  sim::Scene s = sim::load_scene(kData / "tests/sim/small_pour.toml", kData);
  s.until = 0.04;
  const fs::path out = temp_dir("run");
  sim::RunOptions o;
  o.out = out / "r";
  o.progress = false;
  const sim::RunSummary r = sim::run_scene(s, o);
  EXPECT_FALSE(r.interrupted);
  EXPECT_GE(r.time, 0.04);
  EXPECT_EQ(r.clumps, 40);
  const std::string series = read_file(o.out / "series.csv");
  EXPECT_EQ(series.rfind("time_s,kinetic_energy_J,clumps,contacts,mass_cup_kg,cup_Fx_N", 0), 0u);
  EXPECT_GE(std::count(series.begin(), series.end(), '\n'), 3);
  EXPECT_TRUE(fs::exists(o.out / "particles.pvd"));
  EXPECT_TRUE(fs::exists(o.out / "vtk/particles_00000.vtp"));
  EXPECT_NE(read_file(o.out / "state.json").find("\"finished\""), std::string::npos);
  // A second fresh run into the same folder is refused (resume instead).
  EXPECT_THROW(sim::run_scene(s, o), InputError);
  // Resuming a finished run changes nothing.
  const sim::RunSummary again = sim::resume_run(o.out, kData, false);
  EXPECT_EQ(again.state_hash, r.state_hash);
  fs::remove_all(out);
}
