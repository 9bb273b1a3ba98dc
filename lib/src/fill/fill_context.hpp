#pragma once
// What the EDT baseline and the optimiser share once a fill starts: the distance grid, the
// objective's fixed rays, the tolerance, and the containment and membership tests.
#include <memory>

#include "clumpkit/fill/fill_problem.hpp"
#include "distance_grid.hpp"
#include "ray_cache.hpp"

namespace clumpkit::detail {

struct FillContext {
  FillContext(const FillShape& shape, const FillOptions& options);

  const FillShape& shape;
  FillOptions options;
  double tolerance = 0.0;  ///< m
  double size = 0.0;       ///< volume-equivalent diameter, m
  DistanceGrid grid;
  std::unique_ptr<RayCache> cache;

  /// Signed distance (exact when the shape has one, else from the grid), m.
  double distance(const Eigen::Vector3d& p) const;
  /// Largest radius a sphere centred at p may have: tolerance - distance(p).
  double max_radius(const Eigen::Vector3d& p) const { return tolerance - distance(p); }
  /// Gradient of distance() by central differences.
  Eigen::Vector3d distance_gradient(const Eigen::Vector3d& p) const;
  /// Exact membership of a point (ray intervals or the exact distance).
  bool inside(const Eigen::Vector3d& p) const;

  /// The stopping metric and the symmetric difference of a sphere set, on the objective's rays.
  struct Errors {
    double symmetric_difference = 0.0, metric = 0.0;
  };
  Errors errors(const Spheres& spheres) const;
  /// Relative symmetric difference only (the objective); with `removal_cost`, also the rise of
  /// the objective if each sphere alone were removed.
  double objective(const Spheres& spheres, std::vector<double>* removal_cost = nullptr) const;

  /// Shrinks each sphere, where the shape has no exact distance, until its core of radius
  /// r - tolerance passes a membership test on 256 surface points (containment polish).
  void enforce_containment(Spheres& spheres) const;
};

/// Relative principal-moment error of `u` against `s` (each about its own centre of mass).
double inertia_error(const Moments& s, const Moments& u);

/// n points evenly spread on the unit sphere (Fibonacci lattice).
std::vector<Eigen::Vector3d> fibonacci_sphere(int n);

}  // namespace clumpkit::detail
