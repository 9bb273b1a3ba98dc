// Side by side with a peer: clumpkit's PLY and OFF readers against assimp 5.2 (which read those
// formats until docs/hardening.md #22) on real files, the meshes and point sets of CGAL's data
// archive (Debian's libcgal-demo), read at test time. Raw vertices and fanned triangles are
// compared: the same vertex count, the same triangles and signed volume where assimp reads every
// face; where the two differ, only in ways that are assimp's known faults (it drops faces, or
// cannot read the file). Skipped without libcgal-demo.
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "clumpkit/core/error.hpp"
#include "mesh_io/mesh_readers.hpp"

namespace clumpkit {
namespace {

namespace fs = std::filesystem;

struct Read {
  bool ok = false;
  std::size_t vertices = 0, triangles = 0;
  double volume = 0.0, extent = 0.0;  // signed volume of the fanned faces; largest |coordinate|
};

Read ours(const fs::path& p) {
  Read r;
  try {
    const TriangleMesh m =
        p.extension() == ".ply" ? detail::read_ply(p, p.string()) : detail::read_off(p, p.string());
    r.ok = true;
    r.vertices = m.vertices.size();
    r.triangles = m.triangles.size();
    for (const auto& v : m.vertices) r.extent = std::max(r.extent, v.cwiseAbs().maxCoeff());
    for (const auto& t : m.triangles)
      r.volume += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6.0;
  } catch (const InputError& e) {
    ADD_FAILURE() << "clumpkit refused " << p << ": " << e.what();
  }
  return r;
}

Read theirs(const fs::path& p) {
  Read r;
  Assimp::Importer importer;
  const aiScene* s = importer.ReadFile(p.string(), 0);
  if (!s) return r;
  r.ok = true;
  for (unsigned k = 0; k < s->mNumMeshes; ++k) {
    const aiMesh* m = s->mMeshes[k];
    r.vertices += m->mNumVertices;
    for (unsigned f = 0; f < m->mNumFaces; ++f) {
      const aiFace& face = m->mFaces[f];
      for (unsigned j = 1; j + 1 < face.mNumIndices; ++j) {
        const aiVector3D a = m->mVertices[face.mIndices[0]], b = m->mVertices[face.mIndices[j]],
                         c = m->mVertices[face.mIndices[j + 1]];
        r.volume += static_cast<double>(a * (b ^ c)) / 6.0;
        ++r.triangles;
      }
    }
  }
  return r;
}

TEST(MeshReaders, AgreeWithAssimpOnCgalsDataOrAssimpIsTheOneAtFault) {
  const fs::path archive = "/usr/share/doc/libcgal-dev/data.tar.gz";
  if (!fs::exists(archive)) GTEST_SKIP() << "libcgal-demo is not installed";
  const fs::path dir = fs::path(CLUMPKIT_BINARY_DIR) / "test_tmp" / "readers_vs_assimp";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string tar = "tar xzf " + archive.string() + " -C " + dir.string() +
                          " --wildcards 'data/*.off' 'data/*.ply'";
  ASSERT_EQ(std::system(tar.c_str()), 0) << tar;
  int compared = 0, same = 0, dropped = 0, unread = 0, precision = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const fs::path p = entry.path();
    if (p.extension() != ".off" && p.extension() != ".ply") continue;
    SCOPED_TRACE(p.string());
    ++compared;
    const Read a = ours(p), b = theirs(p);
    if (!a.ok) continue;
    if (!b.ok) {  // assimp cannot read it (a comment it does not know, a file without faces)
      ++unread;
      continue;
    }
    EXPECT_EQ(a.vertices, b.vertices);
    if (a.triangles != b.triangles) {  // assimp skips faces: never the other way round
      EXPECT_LT(b.triangles, a.triangles);
      ++dropped;
      continue;
    }
    // assimp stores float coordinates: the same volume within 1e-5, or, for thin or open
    // surfaces far from the origin, within what float coordinates allow (volume ~ extent³).
    const double d = std::abs(a.volume - b.volume);
    if (d <= 1e-5 * std::abs(a.volume) + 1e-12) {
      ++same;
    } else {
      EXPECT_LE(d, 1e-6 * std::pow(a.extent, 3.0));
      ++precision;
    }
  }
  std::printf(
      "%d files: %d the same, %d where assimp reads float, %d where it drops faces, %d it "
      "cannot read\n",
      compared, same, precision, dropped, unread);
  EXPECT_GE(compared, 100);
  EXPECT_GE(same, compared * 8 / 10);
}

}  // namespace
}  // namespace clumpkit
