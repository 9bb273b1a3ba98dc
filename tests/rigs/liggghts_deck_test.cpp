// The LIGGGHTS deck writer (rigs/liggghts_deck.hpp) without LIGGGHTS: the deck carries the
// scene's materials and per-pair laws in type order, each wall as an STL file, each clump
// template in its principal frame with a seed of its own, the procedure's loops with every jump
// landing on a label of its file; dumps are read back or refused naming file and line.
// (tests/peer/liggghts_rigs.py runs decks in LIGGGHTS itself.)
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <tuple>

#include "clumpkit/core/error.hpp"
#include "clumpkit/dem/world.hpp"
#include "clumpkit/geometry/clump_template.hpp"
#include "rigs/liggghts_deck.hpp"

namespace clumpkit::rigs::detail {
namespace {

using Eigen::Vector3d;

// An asymmetric two-sphere clump: its centre of mass is off the spheres' origin and its axes
// are turned, as the rigs' ray-sampled templates are (slightly).
dem::ClumpTypeSettings two_sphere_type(const std::string& name) {
  const Spheres s = {{Vector3d(0.001, 0.0005, 0.0002), 0.002},
                     {Vector3d(-0.0012, 0.0, 0.0007), 0.0015}};
  return {name, make_clump_template(s, 1380.0), "pill"};
}

dem::WorldSettings scene(dem::RollingModel rolling) {
  dem::WorldSettings ws;
  ws.materials = MaterialLibrary::paper_table1();
  ws.rolling_model = rolling;
  ws.clump_types = {two_sphere_type("A"), two_sphere_type("B")};
  ws.walls.push_back({"cup",
                      dem::make_plane(Vector3d::Zero(), Vector3d::UnitZ(), 0.05, 0.05),
                      "organic_glass",
                      {},
                      {}});
  ws.walls.push_back({"blade",
                      dem::make_plane(Vector3d(-0.02, 0, 0.03), Vector3d::UnitX(), 0.04, 0.02),
                      "galvanized_steel",
                      {},
                      {}});
  return ws;
}

Eigen::AlignedBox3d box() {
  return {Vector3d(-0.05, -0.05, -0.01), Vector3d(0.05, 0.05, 0.1)};
}

std::map<std::string, std::string> by_name(const std::vector<DeckFile>& files) {
  std::map<std::string, std::string> m;
  for (const auto& f : files) m[f.name] = f.content;
  return m;
}

std::vector<double> numbers_after(const std::string& text, const std::string& key) {
  const size_t at = text.find(key);
  EXPECT_NE(at, std::string::npos) << key;
  std::istringstream ss(text.substr(at + key.size(), text.find('\n', at) - at - key.size()));
  std::vector<double> v;
  for (double x; ss >> x;) v.push_back(x);
  return v;
}

TEST(LiggghtsDeck, MaterialsAndLawsInTypeOrder) {
  const dem::WorldSettings ws = scene(dem::RollingModel::kCdt);
  const LiggghtsDeck deck(ws, box(), 0.0, 1e-5, 7, "test");
  const std::string in = by_name(deck.files()).at("in.rig");
  // Types: pill (the clumps), organic_glass (cup), galvanized_steel (blade).
  const std::vector<std::string> mats = {"pill", "organic_glass", "galvanized_steel"};
  const auto e = numbers_after(in, "youngsModulus peratomtype");
  ASSERT_EQ(e.size(), 3u);
  for (size_t k = 0; k < 3; ++k) EXPECT_EQ(e[k], ws.materials.get(mats[k]).youngs_modulus);
  const auto mu = numbers_after(in, "coefficientFriction peratomtypepair");
  const auto mur = numbers_after(in, "coefficientRollingFriction peratomtypepair");
  const auto res = numbers_after(in, "coefficientRestitution peratomtypepair");
  ASSERT_EQ(mu.size(), 10u);
  EXPECT_EQ(mu[0], 3);
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < 3; ++j) {
      if (!ws.materials.has_interaction(mats[i], mats[j])) continue;
      const Interaction& x = ws.materials.interaction(mats[i], mats[j]);
      EXPECT_EQ(mu[1 + 3 * i + j], x.static_friction) << mats[i] << "-" << mats[j];
      EXPECT_EQ(mur[1 + 3 * i + j], x.rolling_friction) << mats[i] << "-" << mats[j];
      EXPECT_EQ(res[1 + 3 * i + j], x.restitution) << mats[i] << "-" << mats[j];
    }
  EXPECT_NE(in.find("pair_style gran model hertz tangential history rolling_friction cdt\n"),
            std::string::npos);
  EXPECT_EQ(in.find("cohesion"), std::string::npos);
  EXPECT_EQ(in.find("timestep 1e-05\n") != std::string::npos, true);
  // CDT is LIGGGHTS's own: the only note is the implicit damping's.
  EXPECT_EQ(deck.notes().size(), 1u);
}

TEST(LiggghtsDeck, StandardRollingAndCohesionAreSaidOrWritten) {
  dem::WorldSettings ws = scene(dem::RollingModel::kStandard);
  dem::PairContact pill = dem::PairContact::from(ws.materials.interaction("pill", "pill"));
  pill.cohesion = dem::Cohesion{2e4};
  ws.pair_contacts.push_back({"pill", "pill", pill});
  // A pill-wall pair without friction: LIGGGHTS gets 0, and restitution absent is elastic (1).
  dem::PairContact bare;
  ws.pair_contacts.push_back({"pill", "galvanized_steel", bare});
  const LiggghtsDeck deck(ws, box(), 0.0, 1e-5, 7, "test");
  const std::string in = by_name(deck.files()).at("in.rig");
  EXPECT_NE(in.find("rolling_friction cdt cohesion sjkr"), std::string::npos);
  const auto k = numbers_after(in, "cohesionEnergyDensity peratomtypepair");
  ASSERT_EQ(k.size(), 10u);
  EXPECT_EQ(k[1], 2e4);
  EXPECT_EQ(k[2], 0.0);
  EXPECT_EQ(numbers_after(in, "coefficientFriction peratomtypepair")[3], 0.0);
  EXPECT_EQ(numbers_after(in, "coefficientRestitution peratomtypepair")[7], 1.0);
  bool said = false;
  for (const auto& n : deck.notes())
    said = said || n.find("no 'standard' model") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST(LiggghtsDeck, WallsTemplatesAndSeeds) {
  const dem::WorldSettings ws = scene(dem::RollingModel::kCdt);
  LiggghtsDeck deck(ws, box(), 0.0, 1e-5, 7, "test");
  dem::FactorySettings f;
  f.region = dem::CylinderRegion{Vector3d(0, 0, 0.05), 0.01, 0.02};
  f.mixture = {{"A", 0.4}, {"B", 0.6}};
  f.mass = 0.01;
  f.rate = 0.2;
  f.whole_in_region = false;
  const double t = deck.insert(f);
  EXPECT_NEAR(t, 0.01 / 0.2 + std::sqrt(2 * 0.02 / 9.81), 1e-12);
  deck.finish_insertion(1e-5);
  const auto files = by_name(deck.files());
  const std::string& in = files.at("in.rig");
  // Walls: one ASCII STL each, its facets the mesh's triangles.
  for (const auto& w : ws.walls) {
    const std::string& stl = files.at(w.name + ".stl");
    size_t facets = 0;
    for (size_t at = stl.find("facet normal"); at != std::string::npos;
         at = stl.find("facet normal", at + 1))
      ++facets;
    EXPECT_EQ(facets, w.mesh.triangles.size()) << w.name;
    EXPECT_NE(in.find("fix " + w.name + " all mesh/surface file " + w.name + ".stl"),
              std::string::npos);
  }
  EXPECT_NE(in.find("meshes cup blade"), std::string::npos);
  // Templates in their principal frame: the spheres file's centres are the engine's offsets.
  for (const auto& t2 : ws.clump_types) {
    const ClumpTemplate c = in_principal_frame(t2.clump);
    EXPECT_LT(c.mass.center_of_mass.norm(), 1e-15);
    EXPECT_NEAR(
        (c.mass.inertia_tensor - Eigen::Matrix3d(c.mass.inertia_tensor.diagonal().asDiagonal()))
            .norm(),
        0.0, 1e-25);
    // The same spheres in the source frame as before the move.
    const Spheres a = t2.clump.spheres_in_source_frame(), b = c.spheres_in_source_frame();
    for (size_t k = 0; k < a.size(); ++k) EXPECT_LT((a[k].center - b[k].center).norm(), 1e-15);
    std::istringstream ss(files.at("type_" + t2.name + "_spheres.txt"));
    for (const Sphere& s : c.spheres) {
      double x, y, z, r;
      ss >> x >> y >> z >> r;
      EXPECT_NEAR(x, s.center.x(), 1e-15);
      EXPECT_NEAR(y, s.center.y(), 1e-15);
      EXPECT_NEAR(z, s.center.z(), 1e-15);
      EXPECT_EQ(r, s.radius);
    }
  }
  EXPECT_NE(in.find("pts_type_A 0.4 pts_type_B 0.6"), std::string::npos);
  EXPECT_NE(in.find("insert/rate/region"), std::string::npos);
  EXPECT_NE(in.find("mass 0.01 massrate 0.2"), std::string::npos);
  EXPECT_NE(in.find("all_in no"), std::string::npos);
  EXPECT_NE(in.find("unfix ins1"), std::string::npos);
  // Every seed LIGGGHTS takes is a prime above 10000, and no two are equal (it refuses that).
  std::string all = in + files.at("type_A.liggghts") + files.at("type_B.liggghts");
  std::set<long> seeds;
  int count = 0;
  const std::regex seed_re(R"((?:seed |multisphere |discrete )(\d+))");
  for (auto it = std::sregex_iterator(all.begin(), all.end(), seed_re);
       it != std::sregex_iterator(); ++it) {
    const long s = std::stol((*it)[1]);
    EXPECT_GT(s, 10000);
    for (long d = 2; d * d <= s; ++d) ASSERT_NE(s % d, 0) << s << " is not prime";
    seeds.insert(s);
    ++count;
  }
  EXPECT_EQ(count, 4);  // two templates, the distribution and the insertion
  EXPECT_EQ(int(seeds.size()), count);
}

// A box cut by planes (the discharger's pour region) is the intersection of a block with each
// plane's inner side, and the insertion names the intersection.
TEST(LiggghtsDeck, ACutBoxIsABlockIntersectedWithPlanes) {
  const dem::WorldSettings ws = scene(dem::RollingModel::kCdt);
  LiggghtsDeck deck(ws, box(), 0.0, 1e-5, 7, "test");
  dem::FactorySettings f;
  const Vector3d n = Vector3d(1, 0, 1).normalized();
  f.region = dem::BoxRegion{
      Vector3d(-0.02, -0.01, 0.03), Vector3d(0.02, 0.01, 0.08), {{Vector3d(0, 0, 0.03), n}}};
  f.mixture = {{"A", 1.0}};
  f.mass = 0.01;
  deck.insert(f);
  const std::string in = by_name(deck.files()).at("in.rig");
  EXPECT_NE(in.find("region pour1_box block -0.02 0.02 -0.01 0.01 0.03 0.08 units box\n"),
            std::string::npos)
      << in;
  const std::vector<double> plane = numbers_after(in, "region pour1_cut0 plane ");
  ASSERT_EQ(plane.size(), 6u);
  EXPECT_EQ(plane[2], 0.03);
  EXPECT_NEAR(plane[3], n.x(), 1e-9);  // the deck's numbers have 10 digits
  EXPECT_NEAR(plane[5], n.z(), 1e-9);
  EXPECT_NE(in.find("side in units box\n"), std::string::npos);
  EXPECT_NE(in.find("region pour1 intersect 2 pour1_box pour1_cut0\n"), std::string::npos);
  EXPECT_NE(in.find("region pour1\n"), std::string::npos);  // the insert/pack line's end
}

// Every `jump SELF L` lands on a `label L` of the same file, every `jump FILE [L]` on a file of
// the deck (and its label), and no file has a label twice.
void expect_jumps_land(const std::map<std::string, std::string>& files) {
  std::map<std::string, std::set<std::string>> labels;
  std::vector<std::tuple<std::string, std::string, std::string>> jumps;  // from, to, label
  for (const auto& [name, text] : files) {
    std::istringstream ss(text);
    for (std::string l; std::getline(ss, l);) {
      if (l.rfind("label ", 0) == 0) {
        EXPECT_TRUE(labels[name].insert(l.substr(6)).second) << name << ": " << l;
      }
      for (size_t at = l.find("jump "); at != std::string::npos; at = l.find("jump ", at + 1)) {
        std::istringstream js(l.substr(at + 5, l.find('"', at) - at - 5));
        std::string to, label;
        js >> to >> label;
        jumps.emplace_back(name, to == "SELF" ? name : to, label);
      }
    }
  }
  EXPECT_FALSE(jumps.empty());
  for (const auto& [from, to, label] : jumps) {
    EXPECT_TRUE(files.count(to)) << from << ": jump to a missing file " << to;
    if (!label.empty()) {
      EXPECT_TRUE(labels[to].count(label)) << from << ": jump to " << to << " " << label;
    }
  }
}

TEST(LiggghtsDeck, ProcedureLoopsAreClosed) {
  const dem::WorldSettings ws = scene(dem::RollingModel::kCdt);
  LiggghtsDeck deck(ws, box(), -0.01, 2e-5, 3, "test");
  deck.run(0.1, "pour");
  deck.settle("settling", 0.01, 1.0);
  deck.move_wall("blade", Vector3d(0.04, 0, 0));
  deck.begin_block();
  deck.run("${lift}/0.03", "lifting");
  deck.end_block("block.in", "${lift} > 0");
  deck.stop_wall("blade");
  deck.rotate_wall("cup", Vector3d(0, 0, 0.01), Vector3d::UnitY(), -30.0);
  deck.write_bodies("event_0.txt");
  deck.write_state("bodies.txt", "spheres.txt");
  const auto files = by_name(deck.files());
  const std::string& in = files.at("in.rig");
  expect_jumps_land(files);
  EXPECT_EQ(in.find("${lift}/0.03"), std::string::npos);  // went to the block's file
  EXPECT_NE(in.find("if \"${lift} > 0\" then \"jump block.in\"\nlabel after_block_in\n"),
            std::string::npos);
  EXPECT_NE(files.at("block.in").find("jump in.rig after_block_in\n"), std::string::npos);
  // 0.1 s at 2e-5 s: 5000 steps, in chunks.
  EXPECT_NE(in.find("variable left1 equal ceil((0.1)/2e-05-1e-9)"), std::string::npos);
  EXPECT_NE(in.find("if \"${rms} < 0.01\""), std::string::npos);
  EXPECT_NE(in.find("variable in atom z>-0.01"), std::string::npos);
  EXPECT_NE(in.find("fix move_blade all move/mesh mesh blade linear 0.04 0 0"), std::string::npos);
  EXPECT_NE(in.find("unfix move_blade"), std::string::npos);
  EXPECT_NE(in.find("dump bodies all local 1 bodies.txt"), std::string::npos);
  EXPECT_NE(in.find("dump bodies all local 1 event_0.txt"), std::string::npos);
  // The body computes are defined once however many dumps follow.
  EXPECT_EQ(in.find("compute body_x"), in.rfind("compute body_x"));
  // A negative rpm turns about the reversed axis, at the period of |rpm|.
  EXPECT_NE(in.find("fix move_cup all move/mesh mesh cup rotate origin 0 0 0.01 axis 0 -1 0 "
                    "period 2\n"),
            std::string::npos);
}

TEST(LiggghtsDeck, DumpsAreReadOrRefused) {
  const auto dir = std::filesystem::temp_directory_path() / "clumpkit_liggghts_dump_test";
  std::filesystem::create_directories(dir);
  const auto path = (dir / "d.txt").string();
  const std::string frame0 =
      "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ENTRIES\n1\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n"
      "ITEM: ENTRIES c_x[1] c_m\n9 9\n";
  const std::string frame1 =
      "ITEM: TIMESTEP\n10\nITEM: NUMBER OF ENTRIES\n2\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n"
      "ITEM: ENTRIES c_x[1] c_m\n0.5 0.25\n-1e-3 2\n";
  std::ofstream(path) << frame0 << frame1;
  const auto rows = read_dump_rows(path, 2);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0][0], 0.5);
  EXPECT_EQ(rows[1][0], -1e-3);
  EXPECT_EQ(rows[1][1], 2.0);
  std::ofstream(path) << frame1.substr(0, frame1.size() - 3) << "x\n";
  try {
    read_dump_rows(path, 2);
    FAIL() << "a malformed row was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("d.txt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("line 11"), std::string::npos) << e.what();
  }
  std::ofstream(path) << frame1.substr(0, frame1.find("-1e-3"));
  EXPECT_THROW(read_dump_rows(path, 2), InputError);
  std::ofstream(path) << "";
  EXPECT_THROW(read_dump_rows(path, 2), InputError);
  EXPECT_THROW(read_dump_rows((dir / "missing.txt").string(), 2), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace clumpkit::rigs::detail
