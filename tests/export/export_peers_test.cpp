// The exports load in the real programs: a tiny LIGGGHTS 3.8 deck inserts exported clumps with
// fix particletemplate/multisphere + fix multisphere, and a LAMMPS deck pours the exported
// molecule as rigid/small bodies; each asserts that the program ran, inserted the clumps, and
// took the union's mass and inertia from our files. Skipped when the program is not installed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <regex>

#include "clumpkit/export/exporter.hpp"
#include "export_fixture.hpp"
#include "run_util.hpp"

namespace clumpkit {
namespace {

namespace fs = std::filesystem;

constexpr int kClumps = 4;

// Written out line by line so docs/export.md can quote the deck that is tested.
std::string liggghts_deck(const std::string& snippet_file, const std::string& template_id) {
  return "atom_style      sphere\n"
         "atom_modify     map array\n"
         "boundary        f f f\n"
         "newton          off\n"
         "communicate     single vel yes\n"
         "units           si\n"
         "region          box block -0.02 0.02 -0.02 0.02 0.0 0.04 units box\n"
         "create_box      1 box\n"
         "neighbor        0.001 bin\n"
         "neigh_modify    delay 0\n"
         "fix m1 all property/global youngsModulus peratomtype 1.1e8\n"
         "fix m2 all property/global poissonsRatio peratomtype 0.35\n"
         "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.201\n"
         "fix m4 all property/global coefficientFriction peratomtypepair 1 0.466\n"
         "pair_style gran model hertz tangential history\n"
         "pair_coeff * *\n"
         "timestep 2e-6\n"
         "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0\n"
         "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0\n"
         "include " +
         snippet_file +
         "\n"
         "fix pdd all particledistribution/discrete 32452843 1 " +
         template_id +
         " 1.0\n"
         "region factory block -0.015 0.015 -0.015 0.015 0.008 0.036 units box\n"
         "fix ins all insert/pack seed 32452867 distributiontemplate pdd maxattempt 200 "
         "insert_every once overlapcheck yes all_in yes particles_in_region " +
         std::to_string(kClumps) +
         " region factory\n"
         "fix ms all multisphere\n"
         "thermo_style custom step atoms ke\n"
         "thermo 500\n"
         "run 2000\n";
}

std::string lammps_deck(const std::string& mol_file) {
  return "units           si\n"
         "atom_style      sphere\n"
         "atom_modify     map array\n"
         "boundary        f f f\n"
         "newton          off\n"
         "comm_modify     vel yes\n"
         "fix prop all property/atom mol ghost yes\n"
         "region box block -0.02 0.02 -0.02 0.02 0.0 0.04 units box\n"
         "create_box 1 box\n"
         "neighbor 0.001 bin\n"
         "neigh_modify delay 0\n"
         "pair_style gran/hertz/history 1.0e7 NULL 0.0 NULL 0.5 0\n"
         "pair_coeff * *\n"
         "timestep 1e-6\n"
         "fix grav all gravity 9.81 vector 0 0 -1\n"
         "molecule clump " +
         mol_file +
         "\n"
         "fix rb all rigid/small molecule mol clump\n"
         "region slab block -0.015 0.015 -0.015 0.015 0.01 0.036 units box\n"
         "fix ins all pour " +
         std::to_string(kClumps) +
         " 0 4767548 region slab mol clump rigid rb\n"
         "fix floor all wall/gran hertz/history 1.0e7 NULL 0.0 NULL 0.5 0 zplane 0.0 NULL\n"
         "compute body all rigid/local rb id mass inertiax inertiay inertiaz\n"
         "dump bodies all local 500 bodies.txt c_body[1] c_body[2] c_body[3] c_body[4] "
         "c_body[5]\n"
         "dump_modify bodies format float %.17g\n"
         "thermo_style custom step atoms ke\n"
         "thermo 500\n"
         "run 1000\n";
}

// The numbers on the rest of the line after `label` ("mass = 1.75e-04, radius ..." -> 1.75e-4).
std::vector<double> floats_after(const std::string& text, const std::string& label) {
  const auto a = text.find(label);
  if (a == std::string::npos) return {};
  const auto b = text.find('\n', a);
  const std::string rest = text.substr(a + label.size(), b - a - label.size());
  static const std::regex number(R"([-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)");
  std::vector<double> v;
  for (auto it = std::sregex_iterator(rest.begin(), rest.end(), number);
       it != std::sregex_iterator(); ++it)
    v.push_back(std::stod(it->str()));
  return v;
}

std::vector<double> sorted_moments(const ClumpTemplate& c) {
  std::vector<double> v = {c.mass.principal_moments[0], c.mass.principal_moments[1],
                           c.mass.principal_moments[2]};
  std::sort(v.begin(), v.end());
  return v;
}

// "Loop time of T on P procs for N steps with M atoms" (LIGGGHTS and LAMMPS): {N, M}.
std::pair<long, long> loop_steps_atoms(const std::string& log) {
  std::smatch m;
  static const std::regex loop(R"(Loop time of \S+ on \d+ procs for (\d+) steps with (\d+) atoms)");
  if (!std::regex_search(log, m, loop)) return {-1, -1};
  return {std::stol(m[1]), std::stol(m[2])};
}

void liggghts_inserts(const ClumpTemplate& c) {
  const std::string liggghts = test::which("liggghts");
  if (liggghts.empty()) GTEST_SKIP() << "liggghts is not installed (apt-get install liggghts)";
  const fs::path dir = test::scratch_dir("");
  export_clump(c, "liggghts", dir);
  { std::ofstream(dir / "in.deck") << liggghts_deck(c.name + ".liggghts", "pts_" + c.name); }
  const int rc = test::run("cd " + test::quoted(dir) + " && timeout 120 " + liggghts +
                           " -in in.deck -log log.liggghts > screen.txt 2>&1");
  const std::string log = test::slurp(dir / "log.liggghts");
  ASSERT_EQ(rc, 0) << test::slurp(dir / "screen.txt");
  // "... inserted 4 particle templates (mass ...) at step 1"
  std::smatch m;
  ASSERT_TRUE(std::regex_search(log, m, std::regex(R"(inserted (\d+) particle templates)"))) << log;
  EXPECT_EQ(std::stoi(m[1]), kClumps);
  // All steps ran, with every sphere of every clump still in the box.
  const auto [steps, atoms] = loop_steps_atoms(log);
  EXPECT_EQ(steps, 2000);
  EXPECT_EQ(atoms, static_cast<long>(kClumps * c.spheres.size()));
  // LIGGGHTS echoes the template's mass and principal moments (printf %e: 7 digits).
  const auto mass = floats_after(log, "   mass = ");
  ASSERT_FALSE(mass.empty()) << log;
  test::expect_rel(mass[0], c.mass.mass, 1e-6, "LIGGGHTS template mass");
  auto moments = floats_after(log, "Principal moments of inertia_: ");
  ASSERT_EQ(moments.size(), 3u) << log;
  std::sort(moments.begin(), moments.end());
  const auto ours = sorted_moments(c);
  for (int k = 0; k < 3; ++k)
    test::expect_rel(moments[k], ours[k], 1e-6, "LIGGGHTS principal moment");
}

void lammps_uses_the_union(const ClumpTemplate& c) {
  const std::string lmp = test::which("lmp");
  if (lmp.empty()) GTEST_SKIP() << "lmp is not installed (apt-get install lammps)";
  const fs::path dir = test::scratch_dir("");
  export_clump(c, "lammps", dir);
  { std::ofstream(dir / "in.deck") << lammps_deck(c.name + ".mol"); }
  const int rc = test::run("cd " + test::quoted(dir) + " && OMP_NUM_THREADS=1 timeout 120 " + lmp +
                           " -nocite -in in.deck -log log.lammps > screen.txt 2>&1");
  const std::string log = test::slurp(dir / "log.lammps");
  ASSERT_EQ(rc, 0) << test::slurp(dir / "screen.txt");
  std::smatch m;
  ASSERT_TRUE(
      std::regex_search(log, m, std::regex(R"(Read molecule template clump:[\s\S]*?(\d+) atoms)")))
      << log;
  EXPECT_EQ(std::stoul(m[1]), c.spheres.size());
  const auto [steps, atoms] = loop_steps_atoms(log);
  EXPECT_EQ(steps, 1000);
  EXPECT_EQ(atoms, static_cast<long>(kClumps * c.spheres.size()));
  // dump local: "ITEM: ENTRIES ..." then one line per body: id mass Ix Iy Iz
  const auto lines = test::lines_of(test::slurp(dir / "bodies.txt"));
  std::vector<std::vector<double>> last;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].rfind("ITEM: ENTRIES", 0) == 0) {
      last.clear();
      for (size_t j = i + 1; j < lines.size() && lines[j].rfind("ITEM:", 0) != 0; ++j)
        last.push_back(test::numbers(lines[j]));
    }
  }
  ASSERT_EQ(last.size(), static_cast<size_t>(kClumps)) << test::slurp(dir / "bodies.txt");
  for (const auto& body : last) {
    ASSERT_EQ(body.size(), 5u);
    test::expect_rel(body[1], c.mass.mass, 1e-12, "LAMMPS body mass");
    std::vector<double> moments(body.begin() + 2, body.end());
    std::sort(moments.begin(), moments.end());
    const auto ours = sorted_moments(c);
    for (int k = 0; k < 3; ++k)
      test::expect_rel(moments[k], ours[k], 1e-12, "LAMMPS principal moment");
  }
}

TEST(ExportPeers, LiggghtsInsertsTheExportedClumps) {
  liggghts_inserts(test::pill_template());
}

// Unequal radii, no symmetry: LIGGGHTS takes the centre of mass at the template origin and the
// tensor as given, so the centroid-principal frame is what makes this right.
TEST(ExportPeers, LiggghtsInsertsAnAsymmetricClump) {
  liggghts_inserts(test::asymmetric_template());
}

// Where users outgrow one machine, clumps run in LIGGGHTS with MPI. The same deck on two ranks
// split at z = 20 mm, the clumps inserted wholly above that plane, falling 60 000 steps onto the
// floor: each clump must pass from one rank to the other and land whole and rigid (its spheres'
// distances as in the template).
TEST(ExportPeers, LiggghtsRunsAnAsymmetricClumpAcrossTwoMpiRanks) {
  const std::string liggghts = test::which("liggghts"), mpirun = test::which("mpirun");
  if (liggghts.empty() || mpirun.empty())
    GTEST_SKIP() << "liggghts or mpirun is not installed (apt-get install liggghts openmpi-bin)";
  // Containers often forbid the cross-memory attach OpenMPI's shared-memory transport uses by
  // default; a machine where MPI itself cannot start two ranks skips (this test is about
  // LIGGGHTS' clumps across ranks, not about the machine's MPI).
  const std::string mpi = "OMPI_MCA_btl_vader_single_copy_mechanism=none timeout 300 " + mpirun +
                          " --allow-run-as-root --oversubscribe -np 2 ";
  if (test::run(mpi + "true > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "mpirun cannot start two ranks on this machine";
  const ClumpTemplate& c = test::asymmetric_template();
  const fs::path dir = test::scratch_dir("");
  export_clump(c, "liggghts", dir);
  std::string deck = liggghts_deck(c.name + ".liggghts", "pts_" + c.name);
  auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = deck.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    deck.replace(at, from.size(), to);
  };
  replace("boundary ", "processors      1 1 2\nboundary ");
  replace("0.008 0.036 units box", "0.022 0.036 units box");
  replace("thermo 500\nrun 2000\n",
          "thermo 10000\ndump fin all custom 60000 fin.txt id x y z radius\n"
          "dump_modify fin sort id format \"%d %.17g %.17g %.17g %.17g\"\nrun 60000\n");
  { std::ofstream(dir / "in.deck") << deck; }
  const int rc = test::run("cd " + test::quoted(dir) + " && " + mpi + liggghts +
                           " -in in.deck -log log.liggghts > screen.txt 2>&1");
  const std::string log = test::slurp(dir / "log.liggghts");
  ASSERT_EQ(rc, 0) << test::slurp(dir / "screen.txt");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(log, m, std::regex(R"(Loop time of \S+ on (\d+) procs)"))) << log;
  EXPECT_EQ(std::stoi(m[1]), 2);
  const auto [steps, atoms] = loop_steps_atoms(log);
  EXPECT_EQ(steps, 60000);
  const size_t n = c.spheres.size();
  ASSERT_EQ(atoms, static_cast<long>(kClumps * n));
  // The last dump: id x y z radius per sphere, ids in insertion order, n per clump.
  const auto lines = test::lines_of(test::slurp(dir / "fin.txt"));
  std::vector<std::vector<double>> rows;
  for (size_t i = 0; i < lines.size(); ++i)
    if (lines[i].rfind("ITEM: ATOMS", 0) == 0) {
      rows.clear();
      for (size_t j = i + 1; j < lines.size() && lines[j].rfind("ITEM:", 0) != 0; ++j)
        rows.push_back(test::numbers(lines[j]));
    }
  ASSERT_EQ(rows.size(), kClumps * n);
  for (int k = 0; k < kClumps; ++k) {
    double lowest = INFINITY, z_sum = 0.0;
    for (size_t a = 0; a < n; ++a) {
      const auto& p = rows[k * n + a];
      ASSERT_EQ(p.size(), 5u);
      test::expect_rel(p[4], c.spheres[a].radius, 1e-12, "sphere radius in LIGGGHTS");
      lowest = std::min(lowest, p[3] - p[4]);
      for (size_t b = a + 1; b < n; ++b) {
        const auto& q = rows[k * n + b];
        const double d = std::hypot(p[1] - q[1], p[2] - q[2], p[3] - q[3]);
        test::expect_rel(d, (c.spheres[a].center - c.spheres[b].center).norm(), 1e-6,
                         "distance between two spheres of one clump");
      }
      z_sum += p[3];
    }
    EXPECT_LT(z_sum / n, 0.02) << "clump " << k << " stayed on the upper rank";
    // Resting on the floor (or on another clump; then its lowest point is above the floor).
    EXPECT_GT(lowest, -1e-4) << "clump " << k << " sank through the floor";
  }
}

TEST(ExportPeers, LammpsReadsTheMoleculeAndUsesTheUnionMassProperties) {
  lammps_uses_the_union(test::pill_template());
}

TEST(ExportPeers, LammpsUsesTheUnionMassPropertiesOfAnAsymmetricClump) {
  lammps_uses_the_union(test::asymmetric_template());
}

}  // namespace
}  // namespace clumpkit
