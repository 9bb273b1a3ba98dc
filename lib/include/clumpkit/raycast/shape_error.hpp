#pragma once
/// How far a clump is from the shape it stands for. One pass of parallel rays over the union of
/// both bounding boxes carries four interval channels — shape, clump (sphere union), shape XOR
/// clump, shape AND clump — so every figure comes from the same lines and their differences are
/// sampled with correlated, hence small, noise. The 95 % intervals come from the spread of the
/// 3 x replicates independent jittered grids (geometry/ray_moments.hpp). Surface distances are
/// taken between points sampled uniformly on each surface and the other surface, exactly.
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>

#include "clumpkit/geometry/clump_template.hpp"
#include "clumpkit/geometry/mass_properties.hpp"
#include "clumpkit/geometry/sphere.hpp"
#include "clumpkit/raycast/surface_solid.hpp"

namespace clumpkit {

struct ShapeErrorOptions {
  RaySamplingOptions sampling;          ///< rays (total), replicates, seed, threads
  std::size_t surface_samples = 20000;  ///< points sampled on each surface for the distances
  double density = 1000.0;              ///< kg/m^3: scales masses and moments of inertia
  /// A principal axis is compared only if its moment differs from the other two by more than
  /// this fraction of the largest moment (and by 4 sampled 95 % half-widths) in both solids:
  /// the axes of (near-)equal moments are arbitrary within their plane.
  double distinct_moments = 2e-3;
};

struct ShapeError {
  MassProperties shape, clump;  ///< each about its own centre of mass, in the shape's frame
  MassPropertiesCI shape_ci, clump_ci;
  Estimate volume_rel_error;     ///< (V_clump - V_shape) / V_shape
  Estimate sym_diff_volume;      ///< |shape XOR clump|, m^3
  Estimate sym_diff_rel;         ///< |shape XOR clump| / V_shape
  Estimate intersection_volume;  ///< |shape AND clump|, m^3
  Estimate com_offset;           ///< |com_clump - com_shape|, m
  double size = 0.0;             ///< the shape's equivalent-sphere diameter (6V/pi)^(1/3), m
  Estimate com_offset_rel;       ///< com_offset / size
  std::array<Estimate, 3> moments_rel_error;  ///< per principal moment (ascending), clump vs shape
  /// Largest angle between corresponding principal axes that are distinct in both solids, deg;
  /// empty when no axis is distinct (e.g. a sphere).
  std::optional<double> axis_angle_deg;
  int axes_compared = 0;
  double hausdorff = 0.0;              ///< max of both directed maxima, m (sampled: a lower bound)
  double mean_surface_distance = 0.0;  ///< mean of both directed means, m
  double shape_to_clump_max = 0.0, shape_to_clump_mean = 0.0;  ///< from shape surface points, m
  /// From points on the union's outer surface, m (walls of enclosed voids left out).
  double clump_to_shape_max = 0.0, clump_to_shape_mean = 0.0;
  /// Share of the union's boundary area that walls enclosed voids (left out above).
  double void_wall_fraction = 0.0;
  std::size_t spheres = 0;
  std::int64_t rays = 0;
  int replicates = 0;
  std::uint64_t seed = 0;
  std::size_t surface_samples = 0;
  long long unresolved_lines = 0;  ///< mesh lines whose crossings could not be paired
  double seconds = 0.0;
};

/// Compares `shape` with the union of `spheres` (given in the shape's frame, metres). Throws
/// InputError for no spheres, a non-finite centre or a non-positive radius ("clump",
/// "spheres[i]") and for a non-positive ray or sample count.
ShapeError shape_error(const SurfaceSolid& shape, const Spheres& spheres,
                       const ShapeErrorOptions& options = {});

/// Measures a clump template against its source shape: the template's spheres are mapped back
/// to the shape's frame (rotation, translation), the density is the template's, and the figures
/// (to_json) are stored in `clump.error`. Returns them as well.
ShapeError record_shape_error(ClumpTemplate& clump, const SurfaceSolid& shape,
                              ShapeErrorOptions options = {});

/// The figures as JSON, SI units; keys as documented in docs/shape_error.md.
nlohmann::json to_json(const ShapeError& e);

}  // namespace clumpkit
