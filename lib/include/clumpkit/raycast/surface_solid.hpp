#pragma once
/// A solid whose surface can be sampled and measured: what the shape-error analysis compares (the
/// target shape, and the clump's sphere union).
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "clumpkit/geometry/ray_solid.hpp"

namespace clumpkit {

class SurfaceSolid : public RaySolid {
 public:
  /// Unsigned distance from `p` to the surface, metres (exact for every implementation here).
  virtual double surface_distance(const Eigen::Vector3d& p) const = 0;
  /// `n` points distributed uniformly by area over the surface, metres; deterministic for a seed.
  virtual std::vector<Eigen::Vector3d> sample_surface(std::size_t n, std::uint64_t seed) const = 0;
  /// Lines along which the solid could not tell inside from outside (meshes only; see
  /// MeshSolid). Analytic solids never fail.
  virtual long long unresolved_lines() const { return 0; }
};

/// Counter-based uniform numbers in [0, 1) (SplitMix64), so samples do not depend on threads.
class SplitMix {
 public:
  explicit SplitMix(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next();
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

}  // namespace clumpkit
