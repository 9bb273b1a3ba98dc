#pragma once
/// What the general fill methods (EDT baseline, optimiser) share: the shape to fill, the stopping
/// rules and constraints, the result, and an independent measurement of the result's error.
/// Frames: everything here is in the shape's own (source) frame; metres.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "clumpkit/geometry/clump_template.hpp"
#include "clumpkit/geometry/ray_moments.hpp"
#include "clumpkit/geometry/ray_solid.hpp"
#include "clumpkit/geometry/sphere.hpp"

namespace clumpkit {

/// A closed solid to fill: ray intervals (required) and, when known, an exact signed distance
/// (negative inside). Without it, distances come from a grid built from the ray intervals and
/// containment is enforced by point-membership tests on the ray intervals.
struct FillShape {
  std::shared_ptr<const RaySolid> solid;
  std::function<double(const Eigen::Vector3d&)> exact_distance;
  std::string where;  ///< names the shape in messages (file or bundled name)
};

/// A shape whose exact signed distance is the unsigned distance to its surface, negative where
/// the solid's x-ray intervals hold the point (a mesh solid: raycast's surface_distance).
FillShape fill_shape_with_surface_distance(
    std::shared_ptr<const RaySolid> solid,
    std::function<double(const Eigen::Vector3d&)> surface_distance, std::string where);

/// The same for a solid that measures its own surface distance (raycast's SurfaceSolid: a mesh
/// or an analytic surface), as `clumpkit fill` and a model's shape_resolution refill use it.
template <class Solid>
FillShape fill_shape_with_surface_distance(std::shared_ptr<const Solid> solid, std::string where) {
  return fill_shape_with_surface_distance(
      solid, [solid](const Eigen::Vector3d& p) { return solid->surface_distance(p); },
      std::move(where));
}

enum class FillMetric { SymmetricDifference, Volume, Inertia };
const char* to_string(FillMetric m);
/// "symmetric_difference" | "volume" | "inertia"; throws InputError(field "--metric").
FillMetric parse_fill_metric(const std::string& s);

struct FillOptions {
  int spheres = 0;         ///< sphere budget; 0: none (then max_error is required)
  double max_error = 0.0;  ///< error target on `metric` (relative, e.g. 0.05); 0: none
  FillMetric metric = FillMetric::SymmetricDifference;
  double min_radius = 0.0;     ///< m
  double tolerance = -1.0;     ///< m a sphere may leave the shape by; < 0: 1 % of the
                               ///< volume-equivalent diameter
  int max_spheres = 400;       ///< cap when only an error target is given
  int grid = 96;               ///< distance-grid cells along the longest side of the bounds
  std::int64_t rays = 60'000;  ///< rays of the objective (fixed set: common random numbers)
  std::uint64_t seed = 1;
  int threads = 0;  ///< 0: all available
};

/// Validates options against the shape; throws InputError naming the option.
void validate_fill_options(const FillOptions& o);

struct FillResult {
  Spheres spheres;             ///< source frame, m
  double error = 0.0;          ///< `metric` on the objective's rays (relative)
  bool target_reached = true;  ///< false when max_error could not be met within the cap
  double tolerance = 0.0;      ///< m, as applied
  nlohmann::json report = nlohmann::json::object();  ///< method details (iterations, history)
};

/// Relative errors of a fill measured on independent rays: |S xor U| / |S|,
/// |V_U - V_S| / V_S, max_k |I_k(U) - I_k(S)| / I_k(S) (principal moments about each own centre of
/// mass). Each with a 95 % half-width.
struct FillMeasurement {
  Estimate symmetric_difference, volume, inertia;
  double shape_volume = 0.0;  ///< m^3
  double value(FillMetric m) const;
  nlohmann::json to_json() const;
};
FillMeasurement measure_fill(const FillShape& shape, const Spheres& spheres,
                             const RaySamplingOptions& sampling);

/// A template (centroid-principal frame, union mass properties) with `method` provenance and the
/// measured `error` filled in; the caller sets `name` and `source`.
ClumpTemplate fill_template(const std::string& method, const FillOptions& options,
                            const FillResult& result, const FillMeasurement& measured,
                            double density, const RaySamplingOptions& sampling);

/// The EDT baseline (the Euclidean-map mode of CLUMP and MSS): voxelise the signed distance,
/// repeatedly place the largest inscribed sphere at the uncovered voxel farthest from the
/// boundary (radius: its distance plus the tolerance), mark the voxels it covers, until the
/// budget, the error target, or no uncovered voxel remains.
FillResult edt_fill(const FillShape& shape, const FillOptions& options);

/// The optimiser: greedy maximum-coverage seeding from the distance field, then joint descent on
/// centres and radii against the ray-sampled symmetric difference (gradients from the exposed
/// sphere surface inside vs outside the shape), with swap moves (remove the least useful sphere,
/// add one where the uncovered volume is largest) and pruning of redundant spheres. Spheres stay
/// within the shape dilated by the tolerance.
FillResult optimal_fill(const FillShape& shape, const FillOptions& options);

}  // namespace clumpkit
