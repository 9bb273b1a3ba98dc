#pragma once
/// Volume integrals by parallel rays. Lines parallel to each coordinate axis are cast through a
/// jittered (stratified) grid over the bounding box; along each line the moments of the inside
/// intervals are integrated exactly, so the only error is the transverse sampling. Each of
/// `replicates` independent jitters per axis gives an unbiased estimate; the spread of the
/// 3 x replicates estimates gives a 95 % confidence interval (Student t).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <vector>

#include "clumpkit/geometry/intervals.hpp"
#include "clumpkit/geometry/ray_solid.hpp"

namespace clumpkit {

/// Raw geometric moments about the origin: m0 = ∫dV [m^3], m1 = ∫x dV [m^4],
/// m2 = ∫x xᵀ dV [m^5].
struct Moments {
  double m0 = 0.0;
  Eigen::Vector3d m1 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d m2 = Eigen::Matrix3d::Zero();
  Moments& operator+=(const Moments& o);
};

struct RaySamplingOptions {
  std::int64_t rays = 1'500'000;  ///< total over all axes and replicates
  int replicates = 4;             ///< independent jitters per axis (>= 2)
  std::uint64_t seed = 1;
  int threads = 0;  ///< 0: all available
};

/// Mean and 95 % half-width of a sampled scalar.
struct Estimate {
  double value = 0.0;
  double ci95 = 0.0;
};

/// Estimate from independent samples (mean, Student-t 95 % half-width of the mean).
Estimate estimate(const std::vector<double>& samples);

/// Per-ray callback: fills `channels[c]` (normalised) for the line through `origin` along `axis`.
using RayChannels = std::function<void(const Eigen::Vector3d& origin, int axis,
                                       std::vector<IntervalList>& channels)>;

/// Integrates `nchannels` interval channels over `box`. Returns, per channel, the moments of each
/// of the 3 * replicates independent estimates (deterministic for a given seed, whatever the
/// thread count).
std::vector<std::vector<Moments>> integrate_rays(const Eigen::AlignedBox3d& box, int nchannels,
                                                 const RayChannels& channels,
                                                 const RaySamplingOptions& options);

/// Convenience: the moments of one solid, as replicate samples.
std::vector<Moments> integrate_solid(const RaySolid& solid, const RaySamplingOptions& options);

/// Adds the exact moments of the inside intervals of one line along `axis` through transverse
/// coordinates (pu, pv) (u = axis+1, v = axis+2, mod 3), weighted by the cell `area`.
void accumulate_moments(const IntervalList& list, int axis, double pu, double pv, double area,
                        Moments& m);

/// Mean over replicate samples.
Moments mean_moments(const std::vector<Moments>& samples);

}  // namespace clumpkit
