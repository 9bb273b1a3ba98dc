// `clumpkit error` end to end: figures for a paper clump, the table and plot, and every kind of
// bad input -> exit status 2 with a message naming what is wrong.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "clumpkit/mesh_io/primitive_meshes.hpp"
#include "clumpkit/mesh_io/write_mesh.hpp"

namespace clumpkit {
namespace {

namespace fs = std::filesystem;

struct CliRun {
  int status;
  std::string out;  // stdout and stderr together
};

CliRun run(const std::string& args) {
  const std::string cmd =
      std::string(CLUMPKIT_BINARY_DIR) + "/apps/clumpkit/clumpkit " + args + " 2>&1";
  CliRun r{-1, ""};
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf;
  while (fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

class ErrorCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // One folder per process: CTest runs each test in its own process, possibly in parallel.
    dir_ = fs::path(CLUMPKIT_BINARY_DIR) / "test_tmp" / ("error_cli_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ASSERT_EQ(
        run("fill pill_A --spheres 12 --rays 100000 -o " + (dir_ / "A12.json").string()).status, 0);
    ASSERT_EQ(run("fill pill_A --spheres 4 --rays 100000 -o " + (dir_ / "A4.json").string()).status,
              0);
    ASSERT_EQ(run("fill pill_C --spheres 2 --rays 100000 -o " + (dir_ / "C2.json").string()).status,
              0);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static std::string path(const std::string& f) { return (dir_ / f).string(); }
  static void write(const std::string& f, const std::string& text) {
    std::ofstream(dir_ / f) << text;
  }
  static fs::path dir_;
};
fs::path ErrorCli::dir_;

TEST_F(ErrorCli, JsonOfAPaperClumpAgainstItsRecordedSource) {
  const CliRun r = run("error " + path("A12.json") + " --rays 200000 --samples 2000 --json -");
  ASSERT_EQ(r.status, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const double vcyl = 3.14159265358979 * 9e-6 * 5.4e-3;
  EXPECT_NEAR(j["volume"]["shape"].get<double>() / vcyl, 1.0, 1e-3);
  EXPECT_LT(j["volume"]["clump"].get<double>(), j["volume"]["shape"].get<double>());
  // The union lies inside the cylinder: XOR = shape - clump.
  EXPECT_NEAR(j["symmetric_difference"]["volume"].get<double>(),
              j["volume"]["shape"].get<double>() - j["volume"]["clump"].get<double>(), 1e-12);
  EXPECT_EQ(j["spheres"], 12);
  EXPECT_EQ(j["rays"], 200000);
  EXPECT_LT(j["center_of_mass_offset"]["rel_to_size"].get<double>(), 1e-3);
  EXPECT_TRUE(j.contains("axis_angle_deg"));
  EXPECT_GT(j["hausdorff"].get<double>(), 0);
  EXPECT_GT(j["mean_surface_distance"].get<double>(), 0);
  // The fill recorded the same kind of figures in the template.
  std::ifstream in(path("A12.json"));
  const nlohmann::json t = nlohmann::json::parse(in);
  ASSERT_TRUE(t.contains("error")) << "fill did not record the shape error";
  EXPECT_NEAR(t["error"]["symmetric_difference"]["rel"].get<double>(),
              j["symmetric_difference"]["rel"].get<double>(), 2e-3);
}

TEST_F(ErrorCli, ExplicitMeshShapeGivesTheSameFigures) {
  write_stl(cylinder_mesh(6.0, 5.4, 1000), dir_ / "cyl_mm.stl");
  const CliRun r = run("error " + path("A12.json") + " --shape " + path("cyl_mm.stl") +
                       " --mesh-units mm --rays 200000 --samples 2000 --json -");
  ASSERT_EQ(r.status, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["volume"]["shape"].get<double>() / (3.14159265358979 * 9e-6 * 5.4e-3), 1.0, 1e-3);
  EXPECT_EQ(j["unresolved_lines"], 0);
}

TEST_F(ErrorCli, TableIsSortedAndPlotted) {
  const std::string svg = path("plot.svg");
  const CliRun r = run("error --table " + path("C2.json") + " " + path("A12.json") + " " +
                       path("A4.json") + " --rays 100000 --samples 1000 --plot " + svg);
  ASSERT_EQ(r.status, 0) << r.out;
  const auto a4 = r.out.find("pill_A_4"), a12 = r.out.find("pill_A_12"),
             c2 = r.out.find("pill_C_2");
  ASSERT_NE(a4, std::string::npos);
  ASSERT_NE(a12, std::string::npos);
  ASSERT_NE(c2, std::string::npos);
  EXPECT_LT(a4, a12);
  EXPECT_LT(a12, c2);
  std::ifstream in(svg);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("<svg"), std::string::npos);
  EXPECT_NE(text.find("pill_A"), std::string::npos);
  EXPECT_NE(text.find("pill_C"), std::string::npos);
}

// Templates filled from the bundled test shapes (issue 4's set) are measured against their source
// without --shape, so one table covers the whole set; `--shape torus` names one too.
TEST_F(ErrorCli, TemplatesOfTheBundledTestShapesAreMeasuredAgainstTheirSource) {
  ASSERT_EQ(run("fill torus --method edt --spheres 8 -o " + path("torus8.json")).status, 0);
  ASSERT_EQ(run("fill rock --method edt --spheres 8 --seed 3 -o " + path("rock8.json")).status, 0);
  const CliRun r = run("error " + path("torus8.json") + " --rays 200000 --samples 2000 --json -");
  ASSERT_EQ(r.status, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const double pi = 3.14159265358979;
  const double torus = 2 * pi * pi * 3e-3 * 1.2e-3 * 1.2e-3;  // 2 pi^2 R r^2
  EXPECT_NEAR(j["volume"]["shape"].get<double>() / torus, 1.0, 2e-3);
  // The fill measured the same clump against the exact torus.
  std::ifstream in(path("torus8.json"));
  const nlohmann::json t = nlohmann::json::parse(in);
  EXPECT_NEAR(t["error"]["symmetric_difference"]["value"].get<double>(),
              j["symmetric_difference"]["rel"].get<double>(), 3e-3);
  const CliRun named =
      run("error " + path("torus8.json") + " --shape torus --rays 200000 --samples 2000 --json -");
  ASSERT_EQ(named.status, 0) << named.out;
  EXPECT_EQ(nlohmann::json::parse(named.out)["symmetric_difference"], j["symmetric_difference"]);
  // The rock is rebuilt with the seed its fill recorded.
  const CliRun rock = run("error " + path("rock8.json") + " --rays 200000 --samples 2000 --json -");
  ASSERT_EQ(rock.status, 0) << rock.out;
  std::ifstream rin(path("rock8.json"));
  EXPECT_NEAR(nlohmann::json::parse(rin)["error"]["symmetric_difference"]["value"].get<double>(),
              nlohmann::json::parse(rock.out)["symmetric_difference"]["rel"].get<double>(), 3e-3);
  const CliRun table =
      run("error --table " + path("torus8.json") + " " + path("rock8.json") + " " +
          path("A4.json") + " --rays 100000 --samples 1000 --plot " + path("set.svg"));
  ASSERT_EQ(table.status, 0) << table.out;
  for (const char* s : {"torus", "rock", "pill_A"})
    EXPECT_NE(table.out.find(s), std::string::npos) << table.out;
}

void expect_refused(const CliRun& r, const std::string& needle) {
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find(needle), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("internal error"), std::string::npos) << r.out;
}

TEST_F(ErrorCli, BadInputExitsTwoWithAClearMessage) {
  // Open mesh.
  TriangleMesh open = box_mesh({1, 1, 1});
  open.triangles.pop_back();
  write_obj(open, dir_ / "open.obj");
  expect_refused(run("error " + path("A12.json") + " --shape " + path("open.obj")),
                 "boundary (open) edges");
  // NaN coordinates.
  write("nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n");
  expect_refused(run("error " + path("A12.json") + " --shape " + path("nan.obj")), "NaN");
  // Empty mesh file.
  write("empty.stl", "");
  expect_refused(run("error " + path("A12.json") + " --shape " + path("empty.stl")), "empty");
  // Clump with no spheres, and with a negative radius.
  std::ifstream in(path("A12.json"));
  nlohmann::json t = nlohmann::json::parse(in);
  nlohmann::json none = t;
  none["spheres"] = nlohmann::json::array();
  write("none.json", none.dump());
  expect_refused(run("error " + path("none.json")), "spheres");
  nlohmann::json neg = t;
  neg["spheres"][3][3] = -0.001;
  write("neg.json", neg.dump());
  expect_refused(run("error " + path("neg.json")), "spheres[3]");
  // No rays.
  expect_refused(run("error " + path("A12.json") + " --rays 0"), "--rays");
  // A template without a source, and no --shape.
  nlohmann::json nosrc = t;
  nosrc.erase("source");
  write("nosrc.json", nosrc.dump());
  expect_refused(run("error " + path("nosrc.json")), "--shape");
  // Several clumps without --table.
  expect_refused(run("error " + path("A12.json") + " " + path("A4.json")), "--table");
}

}  // namespace
}  // namespace clumpkit
