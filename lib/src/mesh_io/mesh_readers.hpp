#pragma once
// The mesh formats clumpkit reads itself. assimp 5.2 (Debian's libassimp5) is not safe on PLY and
// OFF: the fuzzer found inputs on which it loops forever, abort()s, crashes or asks for ~100 GB.
// Its PLY parser re-reads stale bytes of earlier header lines as new elements, so no check in
// front of it can tell what it will do (a comment line after a longer obj_info line became an
// element of 4 294 967 295 instances). Both formats are simple enough to read completely here;
// assimp reads STL and OBJ.
#include <filesystem>
#include <string>

#include "clumpkit/mesh_io/triangle_mesh.hpp"

namespace clumpkit::detail {

/// A word of the file quoted for an error message: bytes that are not printable ASCII become '?'
/// and a long word is cut (a binary file misread as text must not garble the one-line message).
inline std::string shown(const std::string& word) {
  std::string s = "'";
  for (std::size_t i = 0; i < word.size() && i < 40; ++i) {
    const auto c = static_cast<unsigned char>(word[i]);
    s += c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?';
  }
  return s + (word.size() > 40 ? "...'" : "'");
}

/// PLY: ASCII and both binary byte orders, every scalar type. The 'vertex' element's x, y, z and
/// the 'face' element's vertex_indices (or vertex_index) list, polygons fanned into triangles;
/// a 'tristrips' element's strips (-1 restarts a strip) are read too, other elements skipped.
/// Vertices are as in the file (unscaled). Throws InputError naming the file and the header
/// line, body line (ASCII) or body byte (binary) of the first defect: unknown keywords or types,
/// counts the body does not hold, non-numbers, indices naming no vertex.
TriangleMesh read_ply(const std::filesystem::path& path, const std::string& where);

/// OFF (also COFF, NOFF, STOFF...: extra values after a vertex's x y z or a face's indices are
/// ignored): '#' comments and blank lines anywhere, counts on the header line or the next one,
/// one vertex and one face per line, polygons fanned. Throws InputError naming the file and line
/// of the first defect; 4OFF, nOFF and binary OFF are refused as unsupported.
TriangleMesh read_off(const std::filesystem::path& path, const std::string& where);

}  // namespace clumpkit::detail
