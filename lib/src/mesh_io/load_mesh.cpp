#include "clumpkit/mesh_io/load_mesh.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <new>
#include <set>
#include <sstream>
#include <unordered_map>

#include "clumpkit/core/error.hpp"
#include "clumpkit/mesh_io/orientation.hpp"
#include "hole_filling.hpp"
#include "mesh_readers.hpp"

namespace clumpkit {

namespace fs = std::filesystem;

std::size_t weld_vertices(TriangleMesh& mesh, double tol, std::size_t* collapsed) {
  const std::size_t n = mesh.vertices.size();
  std::vector<int> map(n, -1);
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(n);
  // Hash grid of cell size tol: a vertex within tol of a kept one lies in one of the 27 cells
  // around it. Greedy in file order, so the result is deterministic.
  const double cell = tol > 0 ? tol : 1.0;
  auto key = [](std::int64_t i, std::int64_t j, std::int64_t k) {
    return static_cast<std::uint64_t>(i * 73856093) ^ static_cast<std::uint64_t>(j * 19349663) ^
           static_cast<std::uint64_t>(k * 83492791);
  };
  std::unordered_multimap<std::uint64_t, int> grid;
  grid.reserve(n);
  const double tol2 = tol * tol;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = mesh.vertices[i];
    if (!p.allFinite()) {  // never merged: validation must still see and count it
      map[i] = static_cast<int>(kept.size());
      kept.push_back(p);
      continue;
    }
    const Eigen::Vector3d q = p / cell;
    const std::int64_t ci = static_cast<std::int64_t>(std::floor(q[0]));
    const std::int64_t cj = static_cast<std::int64_t>(std::floor(q[1]));
    const std::int64_t ck = static_cast<std::int64_t>(std::floor(q[2]));
    int found = -1;
    for (int di = -1; di <= 1 && found < 0; ++di)
      for (int dj = -1; dj <= 1 && found < 0; ++dj)
        for (int dk = -1; dk <= 1 && found < 0; ++dk) {
          auto range = grid.equal_range(key(ci + di, cj + dj, ck + dk));
          for (auto it = range.first; it != range.second; ++it)
            if ((kept[it->second] - p).squaredNorm() <= tol2) {
              found = it->second;
              break;
            }
        }
    if (found < 0) {
      found = static_cast<int>(kept.size());
      kept.push_back(p);
      grid.emplace(key(ci, cj, ck), found);
    }
    map[i] = found;
  }
  std::size_t dropped = 0;
  std::vector<Eigen::Vector3i> tris;
  tris.reserve(mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    bool in_range = true;
    for (int k = 0; k < 3; ++k)
      in_range = in_range && t[k] >= 0 && static_cast<std::size_t>(t[k]) < n;
    if (!in_range) {  // left for validation to report
      tris.push_back(t);
      continue;
    }
    const Eigen::Vector3i w(map[t[0]], map[t[1]], map[t[2]]);
    if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) {
      ++dropped;
      continue;
    }
    tris.push_back(w);
  }
  if (collapsed) *collapsed = dropped;
  const std::size_t merged = n - kept.size();
  mesh.vertices = std::move(kept);
  mesh.triangles = std::move(tris);
  return merged;
}

namespace {

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext;
}

// STL and OBJ through assimp, unscaled; an index naming no vertex becomes -1 (validate_mesh
// counts it).
TriangleMesh read_with_assimp(const fs::path& path, const std::string& where) {
  Assimp::Importer importer;
  // Only triangles and points/lines are of interest; normals, UVs and materials are not read.
  // No assimp post-processing: its steps (Triangulate, PreTransformVertices, even the structure
  // validation) abort() on corrupt scenes (found by fuzzing). Polygons are fanned here and every
  // index is checked by validate_mesh; the formats read here have no node transforms.
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(path.string(), 0);
  } catch (const std::bad_alloc&) {  // a corrupt count in the file
    throw InputError(where, "",
                     "the mesh importer ran out of memory reading it (a count in the file is "
                     "probably corrupt)");
  }
  if (!scene)
    throw InputError(where, "",
                     std::string("cannot read as a mesh (STL, OBJ): ") + importer.GetErrorString());
  TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    const int base = static_cast<int>(mesh.vertices.size());
    for (unsigned i = 0; i < am->mNumVertices; ++i) {
      const aiVector3D& v = am->mVertices[i];
      mesh.vertices.emplace_back(static_cast<double>(v.x), static_cast<double>(v.y),
                                 static_cast<double>(v.z));
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices < 3 || !face.mIndices) continue;  // points and lines bound no volume
      const auto index = [&](unsigned k) {
        const unsigned i = face.mIndices[k];
        return i < am->mNumVertices ? base + static_cast<int>(i) : -1;  // -1: a bad index
      };
      for (unsigned k = 1; k + 1 < face.mNumIndices; ++k)  // a fan for polygons
        mesh.triangles.emplace_back(index(0), index(k), index(k + 1));
    }
  }
  return mesh;
}

// How many of the triangles `before` run the other way round in `after` (same positions; `after`
// may have more).
std::size_t reversed_count(const std::vector<Eigen::Vector3i>& before,
                           const std::vector<Eigen::Vector3i>& after) {
  std::size_t n = 0;
  for (std::size_t f = 0; f < before.size(); ++f) {
    const Eigen::Vector3i& a = before[f];
    const Eigen::Vector3i& b = after[f];
    n += !(b == a || b == Eigen::Vector3i(a[1], a[2], a[0]) ||
           b == Eigen::Vector3i(a[2], a[0], a[1]));
  }
  return n;
}

}  // namespace

bool is_mesh_file(const fs::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".stl" || ext == ".obj" || ext == ".ply" || ext == ".off";
}

TriangleMesh load_mesh(const fs::path& path, const MeshLoadOptions& opt, MeshReport* report) {
  const std::string where = path.string();
  if (!(opt.scale > 0) || !std::isfinite(opt.scale))
    throw InputError(where, "scale", "must be a positive finite factor to metres");
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw InputError(where, "", "no such mesh file");
  if (fs::file_size(path, ec) == 0) throw InputError(where, "", "empty file (no triangles)");

  const std::string ext = lower_extension(path);
  TriangleMesh mesh;
  if (ext == ".ply")
    mesh = detail::read_ply(path, where);
  else if (ext == ".off")
    mesh = detail::read_off(path, where);
  else if (ext == ".stl" || ext == ".obj")
    mesh = read_with_assimp(path, where);
  else
    throw InputError(where, "",
                     (ext.empty() ? std::string("no file extension to tell the mesh format")
                                  : "unknown mesh format '" + ext + "'") +
                         " (clumpkit reads .stl, .obj, .ply, .off)");
  if (opt.scale != 1.0)
    for (Eigen::Vector3d& v : mesh.vertices) v *= opt.scale;
  if (mesh.triangles.empty()) throw InputError(where, "", "empty mesh (no triangles)");

  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : mesh.vertices)
    if (v.allFinite()) box.extend(v);
  const double diag = box.isEmpty() ? 0.0 : box.diagonal().norm();
  std::size_t collapsed = 0;
  const std::size_t welded = weld_vertices(mesh, opt.weld_tolerance * diag, &collapsed);
  if (mesh.triangles.empty())  // every triangle collapsed (found by fuzzing: accepted as a wall)
    throw InputError(where, "",
                     "empty mesh (all " + std::to_string(collapsed) + " triangles are degenerate)");

  MeshValidateOptions vopt;
  vopt.check_self_intersections = opt.check_self_intersections;
  MeshReport r = validate_mesh(mesh, vopt);
  if (opt.repair_holes && r.holes_repairable()) {
    const std::vector<Eigen::Vector3i> before = mesh.triangles;
    orient_consistently(mesh, where);
    const detail::FilledHoles h = detail::fill_holes(mesh, where, opt.max_hole_edges);
    orient_outward(mesh, where);
    r = validate_mesh(mesh, vopt);
    r.holes_filled = h.holes;
    r.triangles_added = h.triangles_added;
    r.hole_area = h.area_added;
    r.reoriented_faces = reversed_count(before, mesh.triangles);
  } else if ((opt.repair_orientation || opt.repair_holes) && r.orientation_repairable()) {
    const std::size_t reversed = orient_outward(mesh, where);
    r = validate_mesh(mesh, vopt);
    r.reoriented_faces = reversed;
  }
  r.welded_vertices = welded;
  r.collapsed_faces = collapsed;
  // Even an open surface (a wall) must index existing vertices with finite coordinates: those
  // defects are never usable (found by fuzzing: a PLY face "3 1 20" passed as a wall).
  if (r.bad_indices > 0 || r.nonfinite_vertices > 0)
    throw InputError(where, "", r.defects() + ": not a usable mesh");
  if (opt.require_closed) require_closed_solid(r, where);
  if (r.closed_solid() && r.signed_volume < 0) {
    flip_orientation(mesh);
    r.signed_volume = -r.signed_volume;
    r.flipped = true;
  }
  if (report) *report = r;
  return mesh;
}

TriangleMesh load_mesh(const fs::path& path, double scale) {
  MeshLoadOptions opt;
  opt.scale = scale;
  return load_mesh(path, opt);
}

TriangleMesh load_shape_mesh(const ShapeSpec& shape, MeshReport* report) {
  if (shape.kind != ShapeSpec::Kind::Mesh)
    throw InputError(shape.path.string(), "shape.kind", "not a mesh shape");
  MeshLoadOptions opt;
  opt.scale = shape.mesh_scale;
  opt.repair_orientation = shape.repair_orientation;
  opt.repair_holes = shape.repair_holes;
  return load_mesh(shape.mesh, opt, report);
}

}  // namespace clumpkit
