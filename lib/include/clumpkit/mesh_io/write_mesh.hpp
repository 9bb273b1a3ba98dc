#pragma once
/// Writing triangle meshes, atomically (temporary file + rename).
#include <filesystem>

#include "clumpkit/mesh_io/triangle_mesh.hpp"

namespace clumpkit {

/// Binary STL, coordinates in metres times `scale` (e.g. 1000 to write millimetres).
void write_stl(const TriangleMesh& mesh, const std::filesystem::path& path, double scale = 1.0);
/// Wavefront OBJ (v / f lines), coordinates in metres times `scale`.
void write_obj(const TriangleMesh& mesh, const std::filesystem::path& path, double scale = 1.0);

}  // namespace clumpkit
