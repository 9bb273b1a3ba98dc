#pragma once
/// A closed triangle mesh as a solid, intersected by Embree (single precision, watertight
/// "robust" traversal). Every crossing of an axis-parallel line is collected, near-coincident
/// crossings (a line through a shared edge or vertex) are merged by the sign of the outward
/// normal, and the crossings are paired by winding number into inside intervals. A line whose
/// crossings cannot be paired consistently is retried with a tiny transverse shift; lines that
/// still fail are counted (unresolved_lines()) and contribute nothing, never silently.
#include <atomic>
#include <memory>

#include "clumpkit/mesh_io/triangle_mesh.hpp"
#include "clumpkit/raycast/surface_solid.hpp"

namespace clumpkit {

class MeshSolid final : public SurfaceSolid {
 public:
  /// `mesh` must be a closed solid with outward orientation (load_mesh ensures both); throws
  /// InputError for an empty mesh.
  explicit MeshSolid(TriangleMesh mesh);
  ~MeshSolid() override;
  MeshSolid(const MeshSolid&) = delete;
  MeshSolid& operator=(const MeshSolid&) = delete;

  Eigen::AlignedBox3d bounds() const override { return bounds_; }
  void intervals(const Eigen::Vector3d& origin, int axis, IntervalList& out) const override;
  /// Exact distance to the nearest triangle (Embree point query + closest point on triangle).
  double surface_distance(const Eigen::Vector3d& p) const override;
  std::vector<Eigen::Vector3d> sample_surface(std::size_t n, std::uint64_t seed) const override;

  const TriangleMesh& mesh() const { return mesh_; }
  /// Lines whose crossings could not be paired even after retrying (should stay 0 for a valid
  /// mesh); reset by reset_counters().
  long long unresolved_lines() const override { return unresolved_.load(); }
  /// Lines that needed a shifted retry.
  long long retried_lines() const { return retried_.load(); }
  void reset_counters() const;

 private:
  bool try_line(const Eigen::Vector3d& origin, int axis, IntervalList& out) const;

  struct Embree;
  std::unique_ptr<Embree> rtc_;
  TriangleMesh mesh_;
  std::vector<Eigen::Vector3d> normals_;  // unit outward normals per triangle
  std::vector<double> area_cdf_;          // cumulative triangle areas
  Eigen::AlignedBox3d bounds_;
  Eigen::Vector3d offset_;  // Embree sees vertices - offset, for float precision
  double merge_eps_ = 0.0;  // crossings closer than this along a line are one crossing
  mutable std::atomic<long long> unresolved_{0}, retried_{0};
};

}  // namespace clumpkit
