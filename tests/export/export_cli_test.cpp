// `clumpkit export` end to end: every format through the binary, exit status 2 with a one-line
// message naming the option for bad input, and no output left behind.
#include <gtest/gtest.h>

#include "clumpkit/export/exporter.hpp"
#include "export_fixture.hpp"
#include "run_util.hpp"

namespace clumpkit {
namespace {

namespace fs = std::filesystem;

const std::string kCli = std::string(CLUMPKIT_BINARY_DIR) + "/apps/clumpkit/clumpkit";

fs::path saved_template(const fs::path& dir) {
  const fs::path p = dir / "pill.json";
  save_clump(test::pill_template(), p);
  return p;
}

TEST(ExportCli, WritesEveryFormat) {
  const fs::path dir = test::scratch_dir("");
  const fs::path clump = saved_template(dir);
  for (const Exporter& e : exporters()) {
    const fs::path out = dir / std::string(e.name);
    ASSERT_EQ(
        test::run(kCli + " export " + test::quoted(clump) + " --format " + std::string(e.name) +
                  " -o " + test::quoted(out) + " > " + test::quoted(dir / "stdout.txt")),
        0)
        << e.name;
    EXPECT_EQ(test::listing(out).size(), render_export(test::pill_template(), e.name).size() +
                                             (e.name == "mercurydpm" ? 1 : 0))
        << e.name;  // MercuryDPM's files sit in their own subfolder
  }
}

TEST(ExportCli, UnknownFormatExits2NamingFormat) {
  const fs::path dir = test::scratch_dir("");
  const fs::path clump = saved_template(dir);
  const fs::path err = dir / "stderr.txt";
  EXPECT_EQ(test::run(kCli + " export " + test::quoted(clump) + " --format pfc -o " +
                      test::quoted(dir / "out") + " 2> " + test::quoted(err)),
            2);
  const auto lines = test::lines_of(test::slurp(err));
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("--format"), std::string::npos) << lines[0];
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(ExportCli, UnwritablePathExits2AndLeavesNothing) {
  const fs::path dir = test::scratch_dir("");
  const fs::path clump = saved_template(dir);
  const fs::path err = dir / "stderr.txt";
  EXPECT_EQ(test::run(kCli + " export " + test::quoted(clump) + " --format liggghts -o " +
                      test::quoted(dir / "missing" / "out") + " 2> " + test::quoted(err)),
            2);
  EXPECT_NE(test::slurp(err).find("does not exist"), std::string::npos) << test::slurp(err);
  EXPECT_EQ(test::listing(dir), (std::vector<std::string>{"pill.json", "stderr.txt"}));
  // -o naming an existing regular file
  EXPECT_EQ(test::run(kCli + " export " + test::quoted(clump) + " --format vtk -o " +
                      test::quoted(clump) + " 2> " + test::quoted(err)),
            2);
  EXPECT_NE(test::slurp(err).find("-o"), std::string::npos);
}

TEST(ExportCli, BadTemplateExits2NamingTheFile) {
  const fs::path dir = test::scratch_dir("");
  const fs::path bad = dir / "bad.json";
  { std::ofstream(bad) << R"({"format": "clumpkit-clump/1", "spheres": [[0, 0, 0, -1]]})"; }
  const fs::path err = dir / "stderr.txt";
  EXPECT_EQ(test::run(kCli + " export " + test::quoted(bad) + " --format lammps -o " +
                      test::quoted(dir / "out") + " 2> " + test::quoted(err)),
            2);
  EXPECT_NE(test::slurp(err).find("bad.json"), std::string::npos) << test::slurp(err);
  EXPECT_FALSE(fs::exists(dir / "out"));
}

}  // namespace
}  // namespace clumpkit
