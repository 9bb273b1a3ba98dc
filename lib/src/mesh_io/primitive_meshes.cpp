#include "clumpkit/mesh_io/primitive_meshes.hpp"

#include <cmath>
#include <map>
#include <numbers>
#include <utility>

namespace clumpkit {

TriangleMesh box_mesh(const Eigen::Vector3d& s) {
  TriangleMesh m;
  const Eigen::Vector3d h = 0.5 * s;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? h[0] : -h[0], i & 2 ? h[1] : -h[1], i & 4 ? h[2] : -h[2]);
  // Two triangles per face, counter-clockwise seen from outside.
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

TriangleMesh icosphere_mesh(double radius, int subdivisions) {
  TriangleMesh m;
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  const double base[12][3] = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0},
                              {0, -1, p}, {0, 1, p}, {0, -1, -p}, {0, 1, -p},
                              {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  for (const auto& v : base) m.vertices.push_back(Eigen::Vector3d(v[0], v[1], v[2]).normalized());
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      const int id = static_cast<int>(m.vertices.size());
      m.vertices.push_back((m.vertices[a] + m.vertices[b]).normalized());
      mid.emplace(key, id);
      return id;
    };
    std::vector<Eigen::Vector3i> next;
    next.reserve(m.triangles.size() * 4);
    for (const Eigen::Vector3i& t : m.triangles) {
      const int a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]), c = midpoint(t[2], t[0]);
      next.emplace_back(t[0], a, c);
      next.emplace_back(t[1], b, a);
      next.emplace_back(t[2], c, b);
      next.emplace_back(a, b, c);
    }
    m.triangles = std::move(next);
  }
  for (Eigen::Vector3d& v : m.vertices) v *= radius;
  return m;
}

TriangleMesh cylinder_mesh(double diameter, double height, int segments, int rings) {
  TriangleMesh m;
  const double r = 0.5 * diameter;
  for (int k = 0; k <= rings; ++k) {
    const double z = -0.5 * height + height * k / rings;
    for (int i = 0; i < segments; ++i) {
      const double phi = 2.0 * std::numbers::pi * i / segments;
      m.vertices.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
  }
  const int bottom = static_cast<int>(m.vertices.size());
  m.vertices.emplace_back(0.0, 0.0, -0.5 * height);
  const int top = bottom + 1;
  m.vertices.emplace_back(0.0, 0.0, 0.5 * height);
  auto at = [&](int k, int i) { return k * segments + (i % segments); };
  for (int k = 0; k < rings; ++k)
    for (int i = 0; i < segments; ++i) {
      m.triangles.emplace_back(at(k, i), at(k, i + 1), at(k + 1, i + 1));
      m.triangles.emplace_back(at(k, i), at(k + 1, i + 1), at(k + 1, i));
    }
  for (int i = 0; i < segments; ++i) {
    m.triangles.emplace_back(bottom, at(0, i + 1), at(0, i));
    m.triangles.emplace_back(top, at(rings, i), at(rings, i + 1));
  }
  return m;
}

TriangleMesh torus_mesh(double R, double a, int major, int minor) {
  TriangleMesh m;
  for (int i = 0; i < major; ++i) {
    const double phi = 2.0 * std::numbers::pi * i / major;
    for (int j = 0; j < minor; ++j) {
      const double th = 2.0 * std::numbers::pi * j / minor;
      const double rho = R + a * std::cos(th);
      m.vertices.emplace_back(rho * std::cos(phi), rho * std::sin(phi), a * std::sin(th));
    }
  }
  auto at = [&](int i, int j) { return (i % major) * minor + (j % minor); };
  for (int i = 0; i < major; ++i)
    for (int j = 0; j < minor; ++j) {
      m.triangles.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      m.triangles.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  return m;
}

}  // namespace clumpkit
