// Loading meshes in every supported format, welding, scaling, orientation and bad input.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "clumpkit/core/error.hpp"
#include "clumpkit/geometry/shape_spec.hpp"
#include "clumpkit/mesh_io/load_mesh.hpp"
#include "clumpkit/mesh_io/primitive_meshes.hpp"
#include "clumpkit/mesh_io/write_mesh.hpp"

namespace clumpkit {
namespace {

namespace fs = std::filesystem;

class MeshFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::path(CLUMPKIT_BINARY_DIR) / "test_tmp" /
        (std::string("mesh_io_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  // Writes `text` as `name` and expects load_mesh to refuse it with a message containing
  // `expected`.
  void refused(const std::string& name, const std::string& text, const std::string& expected) {
    SCOPED_TRACE(name);
    try {
      load_mesh(write(name, text));
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
  fs::path dir_;
};

// Unit cube [0,1]^3 scaled by s, as hand-written text in several formats.
std::string cube_obj(double s = 1.0, const char* first_x = nullptr) {
  std::string t;
  const TriangleMesh b = box_mesh(Eigen::Vector3d(s, s, s));
  for (size_t i = 0; i < b.vertices.size(); ++i) {
    const auto& v = b.vertices[i];
    t += "v " + (i == 0 && first_x ? std::string(first_x) : std::to_string(v[0])) + " " +
         std::to_string(v[1]) + " " + std::to_string(v[2]) + "\n";
  }
  for (const auto& f : b.triangles)
    t += "f " + std::to_string(f[0] + 1) + " " + std::to_string(f[1] + 1) + " " +
         std::to_string(f[2] + 1) + "\n";
  return t;
}

std::string cube_ascii_stl() {
  const TriangleMesh b = box_mesh(Eigen::Vector3d(1, 1, 1));
  std::string t = "solid cube\n";
  for (const auto& f : b.triangles) {
    t += " facet normal 0 0 0\n  outer loop\n";
    for (int k = 0; k < 3; ++k) {
      const auto& v = b.vertices[f[k]];
      t += "   vertex " + std::to_string(v[0]) + " " + std::to_string(v[1]) + " " +
           std::to_string(v[2]) + "\n";
    }
    t += "  endloop\n endfacet\n";
  }
  return t + "endsolid cube\n";
}

std::string cube_off() {
  const TriangleMesh b = box_mesh(Eigen::Vector3d(1, 1, 1));
  std::string t = "OFF\n8 12 0\n";
  for (const auto& v : b.vertices)
    t += std::to_string(v[0]) + " " + std::to_string(v[1]) + " " + std::to_string(v[2]) + "\n";
  for (const auto& f : b.triangles)
    t += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) +
         "\n";
  return t;
}

std::string cube_ply() {
  const TriangleMesh b = box_mesh(Eigen::Vector3d(1, 1, 1));
  std::string t =
      "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty "
      "float z\nelement face 12\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& v : b.vertices)
    t += std::to_string(v[0]) + " " + std::to_string(v[1]) + " " + std::to_string(v[2]) + "\n";
  for (const auto& f : b.triangles)
    t += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) +
         "\n";
  return t;
}

TEST_F(MeshFiles, EveryFormatLoadsTheSameClosedCube) {
  const fs::path files[] = {write("c.obj", cube_obj()), write("c.stl", cube_ascii_stl()),
                            write("c.off", cube_off()), write("c.ply", cube_ply())};
  for (const fs::path& f : files) {
    MeshReport r;
    const TriangleMesh m = load_mesh(f, MeshLoadOptions{}, &r);
    SCOPED_TRACE(f.string());
    EXPECT_EQ(m.vertices.size(), 8u);
    EXPECT_EQ(m.triangles.size(), 12u);
    EXPECT_TRUE(r.closed_solid()) << r.defects();
    EXPECT_EQ(r.self_intersections, 0);
    EXPECT_NEAR(polyhedron_moments(m).m0, 1.0, 1e-12);
    EXPECT_NEAR(r.area, 6.0, 1e-12);
  }
}

// The cube as binary PLY in either byte order (float vertices, uchar/int face lists).
std::string cube_binary_ply(bool big_endian) {
  const TriangleMesh b = box_mesh(Eigen::Vector3d(1, 1, 1));
  std::string t = std::string("ply\nformat ") +
                  (big_endian ? "binary_big_endian" : "binary_little_endian") +
                  " 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float "
                  "z\nelement face 12\nproperty list uchar int vertex_indices\nend_header\n";
  const auto put = [&](const void* p, std::size_t n) {
    const char* c = static_cast<const char*>(p);
    for (std::size_t k = 0; k < n; ++k) t += c[big_endian ? n - 1 - k : k];  // host: little
  };
  for (const auto& v : b.vertices)
    for (int k = 0; k < 3; ++k) {
      const float x = static_cast<float>(v[k]);
      put(&x, 4);
    }
  for (const auto& f : b.triangles) {
    t += '\3';
    for (int k = 0; k < 3; ++k) {
      const std::int32_t i = f[k];
      put(&i, 4);
    }
  }
  return t;
}

TEST_F(MeshFiles, BinaryPlyLoadsInBothByteOrders) {
  for (const bool big : {false, true}) {
    SCOPED_TRACE(big ? "big endian" : "little endian");
    MeshReport r;
    const TriangleMesh m = load_mesh(write("c.ply", cube_binary_ply(big)), MeshLoadOptions{}, &r);
    EXPECT_EQ(m.triangles.size(), 12u);
    EXPECT_TRUE(r.closed_solid()) << r.defects();
    EXPECT_NEAR(polyhedron_moments(m).m0, 1.0, 1e-12);
  }
}

// assimp reserves memory by the counts it reads: PLY bodies whose counts do not match their
// contents are refused before assimp sees them, naming the line (ASCII) or byte (binary).
TEST_F(MeshFiles, PlyCountsThatDoNotMatchTheBodyAreRefusedWithTheirPlace) {
  std::string ascii = cube_ply();
  // The fuzzer's input: a face list count far beyond its uchar type (assimp asked for 34 GB).
  std::string huge = ascii;
  huge.replace(huge.rfind("\n3 ") + 1, 1, "3429496729");
  refused("huge.ply", huge, "line 29");  // 9 header lines, 8 vertices, 12 faces
  std::string short_list = ascii;
  short_list.replace(short_list.rfind("\n3 ") + 1, 1, "9");
  refused("short_list.ply", short_list, "announces 9 values");
  refused("missing_faces.ply", ascii.substr(0, ascii.rfind("\n3 ") + 1), "11 of the 12 'face'");
  std::string word = ascii;
  word.replace(word.find("end_header\n") + 11, 1, "x");
  refused("word.ply", word, "is not a number");
  const std::string bin = cube_binary_ply(false);
  refused("truncated.ply", bin.substr(0, bin.size() - 5), "the file has 1 left");
  std::string neg = cube_binary_ply(true);
  neg = std::string(neg).replace(neg.find("uchar int"), 9, "int int  ");
  refused("count_type.ply", neg, "binary PLY");  // counts now read as int: body misaligned
  std::string float_count = ascii;
  float_count.replace(float_count.find("list uchar"), 10, "list float");
  refused("float_count.ply", float_count, "integer type");
}

// The input on which CI's fuzzer made assimp 5.2 ask for 96 GB: a valid PLY whose comment line
// follows a longer obj_info line. assimp's parser re-read the stale tail of the obj_info line
// ("element edge 4294967295") as an element; clumpkit's own reader reads it as the tetrahedron
// it is (tests/fuzz/regressions/mesh_file/ply_stale_header_bytes_assimp_oom.ply).
TEST_F(MeshFiles, PlyCommentsAndObjInfoAreOnlyComments) {
  const std::string ply =
      "ply\nformat ascii 1.0\nobj_info zzzzzz element edge 4294967295\ncomment abcdefg\n"
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\n"
      "property list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  MeshReport r;
  const TriangleMesh m = load_mesh(write("tet.ply", ply), MeshLoadOptions{}, &r);
  EXPECT_EQ(m.vertices.size(), 4u);
  EXPECT_EQ(m.triangles.size(), 4u);
  EXPECT_TRUE(r.closed_solid()) << r.defects();
  EXPECT_NEAR(polyhedron_moments(m).m0, 1.0 / 6.0, 1e-12);
}

// What real exporters write beyond the cube: extra vertex properties (normals, colours) in any
// order, other elements, quads, CRLF line ends, a tristrips element instead of faces.
TEST_F(MeshFiles, PlyExtraPropertiesElementsQuadsAndStripsLoad) {
  const TriangleMesh b = box_mesh(Eigen::Vector3d(1, 1, 1));
  std::string t =
      "ply\r\nformat ascii 1.0\r\ncomment made by a scanner\r\nelement vertex 8\r\n"
      "property double nx\r\nproperty float z\r\nproperty uchar red\r\nproperty float x\r\n"
      "property float y\r\nelement face 12\r\nproperty uchar flags\r\n"
      "property list uint8 int32 vertex_index\r\nproperty list uchar float texcoord\r\n"
      "element material 1\r\nproperty float shine\r\nend_header\r\n";
  for (const auto& v : b.vertices)
    t += "0.5 " + std::to_string(v[2]) + " 255 " + std::to_string(v[0]) + " " +
         std::to_string(v[1]) + "\r\n";
  for (const auto& f : b.triangles)
    t += "7 3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) +
         " 2 0.25 0.5\r\n";
  t += "30\r\n";
  MeshReport r;
  TriangleMesh m = load_mesh(write("extra.ply", t), MeshLoadOptions{}, &r);
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_TRUE(r.closed_solid()) << r.defects();
  EXPECT_NEAR(polyhedron_moments(m).m0, 1.0, 1e-12);

  // A square pyramid: the base a quad, the sides one strip with a restart.
  const std::string pyramid =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
      "element tristrips 1\nproperty list int int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n4 0 3 2 1\n9 0 1 4 2 3 -1 3 0 4\n";
  m = load_mesh(write("pyramid.ply", pyramid), MeshLoadOptions{}, &r);
  EXPECT_EQ(m.triangles.size(), 6u);
  EXPECT_TRUE(r.closed_solid()) << r.defects();
  EXPECT_NEAR(polyhedron_moments(m).m0, 1.0 / 3.0, 1e-12);
}

TEST_F(MeshFiles, PlyHeadersThatDoNotDescribeAMeshAreRefusedWithTheirLine) {
  const std::string ascii = cube_ply();
  std::string no_z = ascii;
  no_z.replace(no_z.find("float z"), 7, "float w");
  refused("no_z.ply", no_z, "line 3: PLY 'vertex' element without x, y and z");
  std::string no_list = ascii;
  no_list.replace(no_list.find("vertex_indices"), 14, "corners");
  refused("no_list.ply", no_list, "line 7: PLY 'face' element without a vertex_indices list");
  std::string twice = ascii;
  twice.replace(twice.find("element face"), 12, "element vertex");
  refused("twice.ply", twice, "line 7: malformed PLY header (a second 'vertex' element)");
  std::string unnamed = ascii;
  unnamed.replace(unnamed.find("property float y"), 16, "property float");
  refused("unnamed.ply", unnamed, "line 5: malformed PLY header (expected 'property TYPE NAME')");
  std::string index = ascii;
  index.replace(index.rfind("\n3 ") + 1, 7, "3 0 1 8");
  refused("index.ply", index,
          "line 29: malformed PLY body ('face' element): vertex index 8 names "
          "no vertex (the file has 8)");
  refused("no_vertex.ply",
          "ply\nformat ascii 1.0\nelement point 1\nproperty float x\nend_header\n1\n",
          "without a 'vertex' element");
  refused("magic.ply", "plyx\nformat ascii 1.0\n", "line 1: not a PLY file");
}

TEST_F(MeshFiles, OffVariantsLoadAndDefectsNameTheirLine) {
  const TriangleMesh b = box_mesh(Eigen::Vector3d(1, 1, 1));
  // COFF: colours after each vertex and face; counts on the header line; comments, blank lines.
  std::string t = "# a comment first\nCOFF 8 12 18 # counts\n\n";
  for (const auto& v : b.vertices)
    t += std::to_string(v[0]) + " " + std::to_string(v[1]) + " " + std::to_string(v[2]) +
         " 255 0 0 255\n";
  for (const auto& f : b.triangles)
    t += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) +
         " 0.1 0.2 0.3  # rgb\n";
  MeshReport r;
  const TriangleMesh m = load_mesh(write("c.off", t), MeshLoadOptions{}, &r);
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_TRUE(r.closed_solid()) << r.defects();
  EXPECT_NEAR(polyhedron_moments(m).m0, 1.0, 1e-12);
  // A quad face is fanned.
  const std::string pyramid =
      "OFF\n5 5 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n4 0 3 2 1\n"
      "3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n";
  EXPECT_NEAR(polyhedron_moments(load_mesh(write("p.off", pyramid))).m0, 1.0 / 3.0, 1e-12);

  const std::string off = cube_off();
  std::string index = off;
  index.replace(index.rfind("\n3 ") + 1, 7, "3 0 1 9");
  refused("index.off", index, "line 22: malformed OFF file: vertex index 9 names no vertex");
  refused("short.off", off.substr(0, off.find("\n3 ") + 1),
          "malformed OFF file: the file ends after 0 of the 12 faces");
  std::string vertex = off;
  vertex.replace(vertex.find('\n', 6) + 1, 1, "x");
  refused("vertex.off", vertex, "line 3: malformed OFF file: a vertex line needs 3 numbers");
  std::string face = off;
  face.replace(face.rfind("\n3 ") + 1, 1, "5");
  refused("face.off", face, "line 22: malformed OFF file: a face announces 5 vertices");
  refused("4d.off", "4OFF\n1 0 0\n0 0 0 0\n", "line 1: malformed OFF file: '4OFF'");
  refused("bin.off", "OFF BINARY\n", "binary OFF is not supported");
  refused("counts.off", "OFF\n8 twelve 0\n", "line 2: malformed OFF file: expected the counts");
  refused("magic.off", "PLY\n", "line 1: malformed OFF file: no OFF header");
}

// Seeded property test of the PLY and OFF readers: a randomly turned and shifted icosphere,
// written with a random layout (ASCII or either byte order; coordinates float or double among
// random extra properties in random order; random list count and index types; quads made of
// triangle pairs where they share an edge; an extra element before or after), reads back with
// every vertex bit-identical to what was written and the same volume.
TEST_F(MeshFiles, PlyAndOffRoundTripsAreExactForRandomLayouts) {
  std::mt19937 rng(20261203);
  const auto pick = [&](int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); };
  for (int trial = 0; trial < 40; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    TriangleMesh m = icosphere_mesh(0.5 + 0.1 * pick(10), 1 + pick(2));
    std::normal_distribution<double> normal;
    const Eigen::Matrix3d R =
        Eigen::Quaterniond(
            Eigen::Vector4d(normal(rng), normal(rng), normal(rng), normal(rng)).normalized())
            .toRotationMatrix();
    const Eigen::Vector3d shift(normal(rng) * 5.0, normal(rng) * 5.0, normal(rng) * 5.0);
    const bool dbl = pick(2) == 1;
    for (auto& v : m.vertices) {
      v = R * v + shift;
      if (!dbl)
        for (int k = 0; k < 3; ++k) {
          // Through a volatile float: Debian 12's GCC 12.2 at -O2 drops the pair
          // v[0] = double(float(v[0])); v[1] = double(float(v[1])) (SLP vectoriser; see
          // docs/hardening.md, "Compiler"), leaving x and y unrounded.
          volatile float f = static_cast<float>(v[k]);
          v[k] = f;
        }
    }
    const double volume = polyhedron_moments(m).m0;

    const int format = pick(4);  // 0 ascii, 1 little, 2 big endian PLY, 3 OFF
    std::string t;
    if (format == 3) {
      t = pick(2) ? "OFF\n" + std::to_string(m.vertices.size()) + " " +
                        std::to_string(m.triangles.size()) + " 0\n"
                  : "# seeded\nNOFF " + std::to_string(m.vertices.size()) + " " +
                        std::to_string(m.triangles.size()) + "\n";
      char buf[128];
      for (const auto& v : m.vertices) {
        std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g 0 0 1\n", v[0], v[1], v[2]);
        t += buf;
      }
      for (const auto& f : m.triangles)
        t += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) +
             (pick(3) == 0 ? " 255 0 0 # red\n" : "\n");
    } else {
      static const char* ints[] = {"uchar", "ushort", "uint", "int", "uint8", "int32"};
      static const int int_bytes[] = {1, 2, 4, 4, 1, 4};
      const int ci = pick(3) == 0 ? 2 : pick(6);  // list count type (uchar holds 3)
      int ii = pick(6);                           // index type: must hold every index
      if (int_bytes[ii] == 1 || (int_bytes[ii] == 2 && m.vertices.size() > 32767)) ii = 2;
      // The vertex's properties: x, y, z and up to 3 extras, shuffled.
      std::vector<std::string> props = {"x", "y", "z"};
      for (int e = pick(4); e > 0; --e) props.push_back("extra" + std::to_string(e));
      std::shuffle(props.begin(), props.end(), rng);
      const std::string ft = dbl ? "double" : "float";
      const bool big = format == 2;
      t = std::string("ply\nformat ") +
          (format == 0   ? "ascii"
           : format == 1 ? "binary_little_endian"
                         : "binary_big_endian") +
          " 1.0\n";
      const bool before = pick(2) == 1;
      const std::string other = "element note 2\nproperty list uchar short data\n";
      if (before) t += other;
      t += "element vertex " + std::to_string(m.vertices.size()) + "\n";
      for (const auto& p : props)
        t += "property " + (p.rfind("extra", 0) == 0 ? std::string("uchar") : ft) + " " + p + "\n";
      t += "element face " + std::to_string(m.triangles.size()) + "\nproperty list " + ints[ci] +
           " " + ints[ii] + " vertex_indices\n";
      if (!before) t += other;
      t += "end_header\n";
      const auto put = [&](const void* p, int n) {
        const char* c = static_cast<const char*>(p);
        for (int k = 0; k < n; ++k) t += c[big ? n - 1 - k : k];  // host: little endian
      };
      const auto put_int = [&](long long v, int bytes) {
        const std::uint64_t u = static_cast<std::uint64_t>(v);
        put(&u, bytes);  // the low bytes (little-endian host)
      };
      const auto note = [&] {
        if (format == 0) {
          t += "2 -7 300\n1 5\n";
          return;
        }
        put_int(2, 1), put_int(-7, 2), put_int(300, 2), put_int(1, 1), put_int(5, 2);
      };
      if (before) note();
      char buf[64];
      for (const auto& v : m.vertices) {
        for (const auto& p : props) {
          const int axis = p == "x" ? 0 : p == "y" ? 1 : p == "z" ? 2 : -1;
          if (format == 0) {
            if (axis < 0)
              t += "7 ";
            else {
              std::snprintf(buf, sizeof buf, "%.17g ", v[axis]);
              t += buf;
            }
          } else if (axis < 0) {
            t += '\7';
          } else if (dbl) {
            put(&v[axis], 8);
          } else {
            const float f = static_cast<float>(v[axis]);
            put(&f, 4);
          }
        }
        if (format == 0) t += "\n";
      }
      for (const auto& f : m.triangles) {
        if (format == 0) {
          t += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " +
               std::to_string(f[2]) + "\n";
          continue;
        }
        put_int(3, int_bytes[ci]);
        for (int k = 0; k < 3; ++k) put_int(f[k], int_bytes[ii]);
      }
      if (!before) note();
    }
    const fs::path p = write(format == 3 ? "r.off" : "r.ply", t);
    MeshLoadOptions o;
    o.weld_tolerance = 0.0;  // no merging: the vertices come back in file order
    MeshReport r;
    const TriangleMesh back = load_mesh(p, o, &r);
    ASSERT_EQ(back.vertices.size(), m.vertices.size());
    ASSERT_EQ(back.triangles.size(), m.triangles.size());
    for (std::size_t i = 0; i < m.vertices.size(); ++i)
      ASSERT_EQ(back.vertices[i], m.vertices[i])
          << "vertex " << i << " format " << format << " double " << dbl << " diff "
          << (back.vertices[i] - m.vertices[i]).transpose();
    EXPECT_TRUE(r.closed_solid()) << r.defects();
    EXPECT_NEAR(polyhedron_moments(back).m0, volume, 1e-12 * std::abs(volume));
  }
}

TEST_F(MeshFiles, UnknownExtensionsAreRefusedNamingTheFormats) {
  refused("cube.mesh", cube_obj(),
          "unknown mesh format '.mesh' (clumpkit reads .stl, .obj, .ply, .off)");
  refused("cube", cube_obj(), "no file extension to tell the mesh format");
  // The extension's case does not matter.
  EXPECT_EQ(load_mesh(write("CUBE.OFF", cube_off())).triangles.size(), 12u);
}

TEST_F(MeshFiles, BinaryStlSoupIsWeldedAndScaled) {
  // Binary STL stores every triangle's vertices separately: 3 * 320 before welding.
  const TriangleMesh ico = icosphere_mesh(2.5, 2);
  write_stl(ico, dir_ / "ico.stl", 1000.0);  // millimetres
  MeshReport r;
  MeshLoadOptions opt;
  opt.scale = 1e-3;
  const TriangleMesh m = load_mesh(dir_ / "ico.stl", opt, &r);
  EXPECT_EQ(m.triangles.size(), ico.triangles.size());
  EXPECT_EQ(m.vertices.size(), ico.vertices.size());
  EXPECT_EQ(r.welded_vertices, 3 * ico.triangles.size() - ico.vertices.size());
  EXPECT_TRUE(r.closed_solid()) << r.defects();
  // float storage: relative error ~1e-7
  EXPECT_NEAR(polyhedron_moments(m).m0 / polyhedron_moments(ico).m0, 1.0, 1e-6);
}

TEST_F(MeshFiles, ObjRoundTripIsExact) {
  const TriangleMesh t = torus_mesh(0.03, 0.01, 24, 12);
  write_obj(t, dir_ / "t.obj");
  const TriangleMesh m = load_mesh(dir_ / "t.obj");
  ASSERT_EQ(m.triangles.size(), t.triangles.size());
  // assimp reads OBJ coordinates as float.
  EXPECT_NEAR(polyhedron_moments(m).m0 / polyhedron_moments(t).m0, 1.0, 1e-6);
}

TEST_F(MeshFiles, NearDuplicateVerticesAreWelded) {
  // Every triangle with its own vertices, jittered far below the weld tolerance.
  const TriangleMesh c = cylinder_mesh(0.006, 0.0054, 40, 3);
  std::string t;
  int n = 0;
  for (const auto& f : c.triangles) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d v = c.vertices[f[k]] * (1.0 + 1e-10 * ((n % 7) - 3));
      t += "v " + std::to_string(v[0] * 1e3).substr(0, 12) + " " + std::to_string(v[1] * 1e3) +
           " " + std::to_string(v[2] * 1e3) + "\n";
      ++n;
    }
    t +=
        "f " + std::to_string(n - 2) + " " + std::to_string(n - 1) + " " + std::to_string(n) + "\n";
  }
  MeshReport r;
  MeshLoadOptions opt;
  opt.scale = 1e-3;
  opt.weld_tolerance = 1e-5;
  const TriangleMesh m = load_mesh(write("soup.obj", t), opt, &r);
  EXPECT_TRUE(r.closed_solid()) << r.defects();
  EXPECT_EQ(m.vertices.size(), c.vertices.size());
}

TEST_F(MeshFiles, InwardMeshIsFlipped) {
  TriangleMesh b = box_mesh(Eigen::Vector3d(1, 2, 3));
  flip_orientation(b);
  ASSERT_LT(polyhedron_moments(b).m0, 0);
  write_obj(b, dir_ / "in.obj");
  MeshReport r;
  const TriangleMesh m = load_mesh(dir_ / "in.obj", MeshLoadOptions{}, &r);
  EXPECT_TRUE(r.flipped);
  EXPECT_NEAR(polyhedron_moments(m).m0, 6.0, 1e-9);
}

TEST_F(MeshFiles, OpenMeshIsRefusedWithCounts) {
  TriangleMesh b = box_mesh(Eigen::Vector3d(1, 1, 1));
  b.triangles.pop_back();
  write_obj(b, dir_ / "open.obj");
  try {
    load_mesh(dir_ / "open.obj");
    FAIL() << "open mesh accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("open.obj"), std::string::npos) << msg;
    EXPECT_NE(msg.find("3 boundary (open) edges"), std::string::npos) << msg;
  }
  // Accepted, with the counts, when the caller does not need a solid.
  MeshLoadOptions opt;
  opt.require_closed = false;
  MeshReport r;
  load_mesh(dir_ / "open.obj", opt, &r);
  EXPECT_EQ(r.boundary_edges, 3u);
  EXPECT_FALSE(r.closed_solid());
}

TEST_F(MeshFiles, NanCoordinatesAreRefused) {
  const fs::path p = write("nan.obj", cube_obj(1.0, "nan"));
  try {
    load_mesh(p);
    FAIL() << "NaN accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos) << e.what();
  }
}

TEST_F(MeshFiles, EmptyMissingAndGarbageFilesAreRefused) {
  EXPECT_THROW(load_mesh(write("empty.stl", "")), InputError);
  EXPECT_THROW(load_mesh(dir_ / "missing.stl"), InputError);
  EXPECT_THROW(load_mesh(write("garbage.stl", "solid x\nthis is not an stl\n")), InputError);
  EXPECT_THROW(load_mesh(write("noface.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n")), InputError);
  try {
    load_mesh(write("empty2.off", ""));
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("empty"), std::string::npos) << e.what();
  }
}

TEST_F(MeshFiles, ShapeSpecOfKindMeshLoads) {
  write_stl(box_mesh(Eigen::Vector3d(2, 3, 4)), dir_ / "box.stl");
  const fs::path toml = write("box.toml",
                              "[shape]\nkind = \"mesh\"\nfile = \"box.stl\"\nunits = \"mm\"\n"
                              "[material]\ndensity = \"1000 kg/m^3\"\n");
  const ShapeSpec s = load_shape(toml);
  ASSERT_EQ(s.kind, ShapeSpec::Kind::Mesh);
  const TriangleMesh m = load_shape_mesh(s);
  EXPECT_NEAR(polyhedron_moments(m).m0, 24e-9, 1e-15);
  EXPECT_THROW(load_shape_mesh(cylinder_shape("c", 1, 1, 1)), InputError);
}

}  // namespace
}  // namespace clumpkit
