// OFF (Geomview's Object File Format; CGAL's and Princeton's shape benchmarks use it), read
// completely here: see mesh_readers.hpp for why not by assimp.
#include <climits>
#include <string>
#include <string_view>
#include <vector>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "mesh_readers.hpp"

namespace clumpkit::detail {

namespace fs = std::filesystem;

TriangleMesh read_off(const fs::path& path, const std::string& where) {
  const std::string text = read_file(path);
  TextLines lines(text, true);
  std::vector<std::string_view> w;
  const auto next = [&] { return lines.next(w); };
  const auto bad = [&](const std::string& what) {
    throw InputError(where, "line " + std::to_string(lines.line()), "malformed OFF file: " + what);
  };
  if (!next()) bad("empty (no OFF header)");
  const std::string magic(w[0]);
  // [ST][C][N][4][n]OFF: texture coordinates, colours and normals only add values after x y z.
  const std::size_t off_at = magic.rfind("OFF");
  if (off_at == std::string::npos || off_at + 3 != magic.size())
    bad("no OFF header (the first line must be OFF, COFF, NOFF, ...)");
  const std::string prefix = magic.substr(0, off_at);
  if (prefix.find('4') != std::string::npos || prefix.find('n') != std::string::npos)
    bad(shown(magic) + " (4-D or n-D vertices) is not supported: only 3-D OFF");
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    const char c = prefix[i];
    const bool st = c == 'S' && i + 1 < prefix.size() && prefix[i + 1] == 'T';
    if (st)
      ++i;
    else if (c != 'C' && c != 'N')
      bad("unknown OFF variant " + shown(magic));
  }
  std::vector<std::string> counts(w.begin() + 1, w.end());
  if (!counts.empty() && counts[0] == "BINARY") bad("binary OFF is not supported: only text OFF");
  if (counts.empty()) {  // counts on their own line
    if (!next()) bad("missing vertex and face counts");
    counts.assign(w.begin(), w.end());
  }
  long long nv = -1, nf = -1;
  if (counts.size() < 2 || counts.size() > 3 || !whole_integer(counts[0], nv) ||
      !whole_integer(counts[1], nf) || nv < 0 || nf < 0)
    bad("expected the counts 'vertices faces [edges]'");
  if (nv > INT_MAX) bad("more vertices than clumpkit can index");
  TriangleMesh mesh;
  for (long long v = 0; v < nv; ++v) {
    if (!next())
      bad("the file ends after " + std::to_string(v) + " of the " + std::to_string(nv) +
          " vertices the header announces");
    double x, y, z;
    if (w.size() < 3 || !whole_number(w[0], x) || !whole_number(w[1], y) || !whole_number(w[2], z))
      bad("a vertex line needs 3 numbers (x y z)");
    mesh.vertices.emplace_back(x, y, z);
  }
  std::vector<long long> ix;
  for (long long f = 0; f < nf; ++f) {
    if (!next())
      bad("the file ends after " + std::to_string(f) + " of the " + std::to_string(nf) +
          " faces the header announces");
    long long k = -1;
    if (!whole_integer(w[0], k) || k < 1)
      bad("a face line starts with its vertex count (" + shown(w[0]) + ")");
    if (k > static_cast<long long>(w.size()) - 1)
      bad("a face announces " + std::string(w[0]) + " vertices, the line has " +
          std::to_string(w.size() - 1));
    ix.clear();
    for (long long j = 1; j <= k; ++j) {
      long long i = -1;
      if (!whole_integer(w[static_cast<std::size_t>(j)], i))
        bad("face index " + shown(w[static_cast<std::size_t>(j)]) + " is not a whole number");
      if (i < 0 || i >= nv)
        bad("vertex index " + std::to_string(i) + " names no vertex (the file has " +
            std::to_string(nv) + ")");
      ix.push_back(i);
    }
    for (std::size_t j = 1; j + 1 < ix.size(); ++j)  // a fan; points and lines bound nothing
      mesh.triangles.emplace_back(static_cast<int>(ix[0]), static_cast<int>(ix[j]),
                                  static_cast<int>(ix[j + 1]));
  }
  return mesh;
}

}  // namespace clumpkit::detail
