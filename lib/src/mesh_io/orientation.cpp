#include "clumpkit/mesh_io/orientation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>
#include <unordered_map>
#include <vector>

#include "clumpkit/core/error.hpp"

namespace clumpkit {
namespace {

// The bodies of a mesh: vertex-connected components of its triangles, each with its triangles,
// signed volume, bounds and a probe point on its surface (the centroid of its largest triangle).
struct Bodies {
  int n = 0;
  std::vector<int> of_triangle;
  std::vector<int> start, triangles;  // body c's triangles: triangles[start[c] .. start[c + 1])
  std::vector<double> volume;
  std::vector<Eigen::AlignedBox3d> box;
  std::vector<Eigen::Vector3d> probe;
};

int find_root(std::vector<int>& parent, int v) {
  while (parent[v] != v) v = parent[v] = parent[parent[v]];
  return v;
}

// With `geometry` false only the labels and the count (enough to see a mesh of one body).
Bodies find_bodies(const TriangleMesh& mesh, bool geometry = true) {
  const int nv = static_cast<int>(mesh.vertices.size());
  std::vector<int> parent(nv);
  std::iota(parent.begin(), parent.end(), 0);
  for (const Eigen::Vector3i& t : mesh.triangles)
    for (int k = 1; k < 3; ++k) {
      const int a = find_root(parent, t[0]), b = find_root(parent, t[k]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  Bodies b;
  std::vector<int> id(nv, -1);
  const std::size_t nt = mesh.triangles.size();
  b.of_triangle.resize(nt);
  for (std::size_t f = 0; f < nt; ++f) {
    int& body = id[find_root(parent, mesh.triangles[f][0])];
    if (body < 0) body = b.n++;
    b.of_triangle[f] = body;
  }
  if (!geometry) return b;
  b.start.assign(b.n + 1, 0);
  for (int c : b.of_triangle) ++b.start[c + 1];
  std::partial_sum(b.start.begin(), b.start.end(), b.start.begin());
  b.triangles.resize(nt);
  std::vector<int> at(b.start.begin(), b.start.end() - 1);
  for (std::size_t f = 0; f < nt; ++f) b.triangles[at[b.of_triangle[f]]++] = static_cast<int>(f);
  b.volume.assign(b.n, 0.0);
  b.box.assign(b.n, Eigen::AlignedBox3d());
  b.probe.assign(b.n, Eigen::Vector3d::Zero());
  std::vector<double> best(b.n, -1.0);
  const Eigen::Vector3d o = mesh_bounds(mesh).center();  // a closed body's volume ignores o
  for (std::size_t f = 0; f < nt; ++f) {
    const Eigen::Vector3i& t = mesh.triangles[f];
    const Eigen::Vector3d &p = mesh.vertices[t[0]], &q = mesh.vertices[t[1]],
                          &r = mesh.vertices[t[2]];
    const int c = b.of_triangle[f];
    b.volume[c] += (p - o).dot((q - o).cross(r - o)) / 6.0;
    b.box[c].extend(p), b.box[c].extend(q), b.box[c].extend(r);
    const double area2 = (q - p).cross(r - p).squaredNorm();
    if (area2 > best[c]) best[c] = area2, b.probe[c] = (p + q + r) / 3.0;
  }
  return b;
}

// Solid angle of triangle (a, b, c) seen from the origin, signed by its orientation
// (Van Oosterom and Strackee, 1983).
double solid_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double num = a.dot(b.cross(c));
  const double den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
  return 2.0 * std::atan2(num, den);
}

// How many other bodies enclose each body's probe point (|winding number| > 1/2).
std::vector<int> nesting_depths(const TriangleMesh& mesh, const Bodies& b) {
  std::vector<int> depth(b.n, 0);
  if (b.n < 2) return depth;
  for (int c = 0; c < b.n; ++c)
    for (int j = 0; j < b.n; ++j) {
      if (j == c || !b.box[j].contains(b.probe[c])) continue;
      double omega = 0.0;
      for (int k = b.start[j]; k < b.start[j + 1]; ++k) {
        const Eigen::Vector3i& t = mesh.triangles[b.triangles[k]];
        omega += solid_angle(mesh.vertices[t[0]] - b.probe[c], mesh.vertices[t[1]] - b.probe[c],
                             mesh.vertices[t[2]] - b.probe[c]);
      }
      if (std::abs(omega) > 2.0 * std::numbers::pi) ++depth[c];  // |w| = |Ω| / 4π > 1/2
    }
  return depth;
}

std::uint64_t edge_key(int a, int b) {
  const auto lo = static_cast<std::uint32_t>(std::min(a, b));
  const auto hi = static_cast<std::uint32_t>(std::max(a, b));
  return std::uint64_t{lo} << 32 | hi;
}

}  // namespace

BodyOrientation body_orientation(const TriangleMesh& mesh) {
  BodyOrientation r;
  r.bodies = static_cast<std::size_t>(find_bodies(mesh, false).n);
  r.solids = r.bodies;
  if (r.bodies < 2) return r;
  const Bodies b = find_bodies(mesh);
  // The fewest bodies to turn, the whole mesh's orientation being free (load_mesh flips a mesh
  // whose total volume is negative).
  const std::vector<int> depth = nesting_depths(mesh, b);
  std::size_t against = 0, along = 0;
  for (int c = 0; c < b.n; ++c) {
    const double v = b.volume[c] * (depth[c] % 2 == 0 ? 1.0 : -1.0);
    against += v < 0.0;
    along += v > 0.0;
  }
  r.misoriented = std::min(against, along);
  r.solids = static_cast<std::size_t>(std::count(depth.begin(), depth.end(), 0));
  return r;
}

namespace {

// The reversals that make neighbouring triangles agree (1: reverse), by a breadth-first walk over
// the triangles: a neighbour must run their shared edge the other way. Edges of one triangle
// (boundary) are allowed only with `allow_boundary`.
std::vector<signed char> consistent_flips(const TriangleMesh& mesh, const std::string& where,
                                          bool allow_boundary) {
  const std::size_t nt = mesh.triangles.size();
  const auto nv = static_cast<long long>(mesh.vertices.size());
  // Each undirected edge's uses: triangle and direction (+1 when it runs from the lower vertex
  // index to the higher).
  struct Uses {
    int n = 0;
    std::array<int, 2> tri{};
    std::array<int, 2> dir{};
  };
  std::unordered_map<std::uint64_t, Uses> edges;
  edges.reserve(2 * nt);
  for (std::size_t f = 0; f < nt; ++f) {
    const Eigen::Vector3i& t = mesh.triangles[f];
    for (int k = 0; k < 3; ++k)
      if (t[k] < 0 || t[k] >= nv || t[k] == t[(k + 1) % 3])
        throw InputError(where, "", "cannot orient a mesh with invalid triangles");
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      Uses& u = edges[edge_key(a, b)];
      if (u.n < 2) u.tri[u.n] = static_cast<int>(f), u.dir[u.n] = a < b ? 1 : -1;
      ++u.n;
    }
  }
  std::size_t bad = 0;
  for (const auto& [key, u] : edges) bad += u.n > 2 || (u.n == 1 && !allow_boundary);
  if (bad > 0)
    throw InputError(where, "",
                     allow_boundary
                         ? fmt::format("{} edges are shared by more than two triangles: only a "
                                       "manifold surface can be oriented",
                                       bad)
                         : fmt::format("{} edges are not shared by exactly two triangles: only a "
                                       "closed, manifold surface can be re-oriented",
                                       bad));
  std::vector<signed char> flip(nt, -1);
  std::vector<int> queue;
  queue.reserve(nt);
  for (std::size_t root = 0; root < nt; ++root) {
    if (flip[root] >= 0) continue;
    flip[root] = 0;
    queue.assign(1, static_cast<int>(root));
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const int f = queue[q];
      const Eigen::Vector3i& t = mesh.triangles[f];
      for (int k = 0; k < 3; ++k) {
        const Uses& u = edges.at(edge_key(t[k], t[(k + 1) % 3]));
        if (u.n < 2) continue;  // a boundary edge: no neighbour across it
        const int side = u.tri[0] == f ? 0 : 1;
        const int g = u.tri[1 - side];
        const int mine = u.dir[side] * (flip[f] ? -1 : 1);
        const signed char want = u.dir[1 - side] == -mine ? 0 : 1;
        if (flip[g] < 0) flip[g] = want, queue.push_back(g);
      }
    }
  }
  // An edge whose two triangles still run it the same way closes a loop that reverses the side:
  // the body is one-sided.
  std::size_t conflicts = 0;
  for (const auto& [key, u] : edges)
    conflicts +=
        u.n == 2 && u.dir[0] * (flip[u.tri[0]] ? -1 : 1) == u.dir[1] * (flip[u.tri[1]] ? -1 : 1);
  if (conflicts > 0)
    throw InputError(where, "",
                     fmt::format("the surface is not orientable ({} edges where its triangles "
                                 "cannot agree on a side): it is one-sided and bounds no volume",
                                 conflicts));
  return flip;
}

std::size_t apply_flips(TriangleMesh& mesh, const std::vector<signed char>& flip) {
  std::size_t n = 0;
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    if (flip[f]) std::swap(mesh.triangles[f][1], mesh.triangles[f][2]), ++n;
  return n;
}

}  // namespace

std::size_t orient_consistently(TriangleMesh& mesh, const std::string& where) {
  return apply_flips(mesh, consistent_flips(mesh, where, true));
}

std::size_t orient_outward(TriangleMesh& mesh, const std::string& where) {
  std::vector<signed char> flip = consistent_flips(mesh, where, false);
  apply_flips(mesh, flip);
  // Every body is now consistent; turn each to face outward by its nesting.
  const Bodies b = find_bodies(mesh);
  const std::vector<int> depth = nesting_depths(mesh, b);
  std::vector<signed char> turn(b.n, 0);
  for (int c = 0; c < b.n; ++c) {
    const double want = depth[c] % 2 == 0 ? 1.0 : -1.0;
    turn[c] = b.volume[c] * want < 0.0;
  }
  std::size_t reversed = 0;
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (turn[b.of_triangle[f]]) {
      std::swap(mesh.triangles[f][1], mesh.triangles[f][2]);
      flip[f] = static_cast<signed char>(!flip[f]);
    }
    reversed += flip[f] != 0;
  }
  return reversed;
}

}  // namespace clumpkit
