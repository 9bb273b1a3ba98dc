// Loading meshes in every supported format, welding, scaling, orientation and bad input.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
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
  const auto refused = [&](const std::string& name, const std::string& text,
                           const std::string& expected) {
    SCOPED_TRACE(name);
    try {
      load_mesh(write(name, text));
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
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
