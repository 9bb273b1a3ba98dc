#pragma once
// A signed distance field on a regular grid, built from ray intervals only (so it works for any
// RaySolid, meshes included). Along every grid line of each axis the distance from each voxel
// centre to the nearest surface crossing is exact; a squared-distance transform
// (Felzenszwalb-Huttenlocher) spreads it over the other two axes, and the minimum over the three
// axes is kept. The result is the exact distance to the set of surface points met by grid lines:
// an upper bound of the true distance, tight to a small fraction of a cell away from edges.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "clumpkit/geometry/ray_solid.hpp"

namespace clumpkit::detail {

struct DistanceGrid {
  Eigen::Vector3d origin;  ///< centre of voxel (0, 0, 0), m
  double h = 0.0;          ///< voxel edge, m
  Eigen::Vector3i n = Eigen::Vector3i::Zero();
  std::vector<float> sdf;            ///< signed distance at voxel centres, m (negative inside)
  std::vector<std::uint8_t> inside;  ///< voxel centre inside the solid

  std::int64_t index(int i, int j, int k) const {
    return (static_cast<std::int64_t>(k) * n.y() + j) * n.x() + i;
  }
  Eigen::Vector3d center(int i, int j, int k) const {
    return origin + h * Eigen::Vector3d(i, j, k);
  }
  std::int64_t size() const { return static_cast<std::int64_t>(n.x()) * n.y() * n.z(); }
  /// Trilinear interpolation; outside the grid, the nearest cell value plus the distance to it.
  double sample(const Eigen::Vector3d& p) const;
};

/// Grid over the solid's bounds with `cells` voxels along the longest side, padded by two cells.
DistanceGrid build_distance_grid(const RaySolid& solid, int cells, int threads);

}  // namespace clumpkit::detail
