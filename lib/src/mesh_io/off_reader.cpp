// OFF (Geomview's Object File Format; CGAL's and Princeton's shape benchmarks use it), read
// completely here: see mesh_readers.hpp for why not by assimp.
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "clumpkit/core/error.hpp"
#include "mesh_readers.hpp"

namespace clumpkit::detail {

namespace fs = std::filesystem;

namespace {

// Splits a line into its space-separated words, dropping a '#' comment.
std::vector<std::string> off_words(const std::string& line) {
  std::vector<std::string> w;
  std::size_t i = 0;
  const auto space = [](char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
  };
  while (i < line.size()) {
    while (i < line.size() && space(line[i])) ++i;
    if (i >= line.size() || line[i] == '#') break;
    const std::size_t b = i;
    while (i < line.size() && !space(line[i]) && line[i] != '#') ++i;
    w.push_back(line.substr(b, i - b));
  }
  return w;
}

bool off_number(const std::string& s, double& v) {
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return end != s.c_str() && *end == '\0';
}

bool off_count(const std::string& s, long long& v) {
  const char* first = s.data();
  const char* last = first + s.size();
  const auto [end, ec] = std::from_chars(first, last, v);
  return ec == std::errc() && end == last;
}

}  // namespace

TriangleMesh read_off(const fs::path& path, const std::string& where) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(where, "", "cannot open the file");
  std::string line;
  std::vector<std::string> w;
  int n = 0;
  const auto next = [&]() {  // the words of the next line that has any
    while (std::getline(in, line)) {
      ++n;
      w = off_words(line);
      if (!w.empty()) return true;
    }
    return false;
  };
  const auto bad = [&](const std::string& what) {
    throw InputError(where, "line " + std::to_string(n), "malformed OFF file: " + what);
  };
  if (!next()) bad("empty (no OFF header)");
  const std::string magic = w[0];
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
    counts = w;
  }
  long long nv = -1, nf = -1;
  if (counts.size() < 2 || counts.size() > 3 || !off_count(counts[0], nv) ||
      !off_count(counts[1], nf) || nv < 0 || nf < 0)
    bad("expected the counts 'vertices faces [edges]'");
  if (nv > INT_MAX) bad("more vertices than clumpkit can index");
  TriangleMesh mesh;
  for (long long v = 0; v < nv; ++v) {
    if (!next())
      bad("the file ends after " + std::to_string(v) + " of the " + std::to_string(nv) +
          " vertices the header announces");
    double x, y, z;
    if (w.size() < 3 || !off_number(w[0], x) || !off_number(w[1], y) || !off_number(w[2], z))
      bad("a vertex line needs 3 numbers (x y z)");
    mesh.vertices.emplace_back(x, y, z);
  }
  std::vector<long long> ix;
  for (long long f = 0; f < nf; ++f) {
    if (!next())
      bad("the file ends after " + std::to_string(f) + " of the " + std::to_string(nf) +
          " faces the header announces");
    long long k = -1;
    if (!off_count(w[0], k) || k < 1)
      bad("a face line starts with its vertex count (" + shown(w[0]) + ")");
    if (k > static_cast<long long>(w.size()) - 1)
      bad("a face announces " + w[0] + " vertices, the line has " + std::to_string(w.size() - 1));
    ix.clear();
    for (long long j = 1; j <= k; ++j) {
      long long i = -1;
      if (!off_count(w[static_cast<std::size_t>(j)], i))
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
