#pragma once
// A fixed set of jittered axis-parallel lines through a box (three axes), with the target
// shape's intervals cached on each. Evaluating a sphere set then only intersects spheres: the
// common random numbers make the sampled symmetric difference a deterministic, piecewise-smooth
// function of the sphere parameters, cheap enough to call inside an optimiser.
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "clumpkit/geometry/ray_moments.hpp"
#include "clumpkit/geometry/ray_solid.hpp"
#include "clumpkit/geometry/sphere.hpp"

namespace clumpkit::detail {

class RayCache {
 public:
  RayCache(const RaySolid& shape, const Eigen::AlignedBox3d& box, std::int64_t rays,
           std::uint64_t seed, int threads);

  struct Eval {
    double xor_volume = 0.0;    ///< m^3, mean of the three axes
    double union_volume = 0.0;  ///< m^3
    Moments union_moments;      ///< only when requested
  };
  /// Spheres outside the box are clipped to it (they are infeasible for the fill anyway). With
  /// `removal_cost`, also the increase of the XOR volume (m^3) if each sphere alone were removed:
  /// its exclusively covered length inside the shape minus that outside.
  Eval evaluate(const Spheres& spheres, bool moments = false,
                std::vector<double>* removal_cost = nullptr) const;

  /// One sphere's neighbourhood for fast trial moves: on every line within `reach` of the
  /// sphere's centre (each axis), the weight function whose integral over a chord is that chord's
  /// contribution to the XOR length given all the other spheres: +1 outside the shape, -1
  /// inside, 0 where another sphere already covers. A trial sphere then costs a binary search per
  /// line instead of a sweep over every sphere. Only the window of each line within `reach` of
  /// the centre is kept (W starts from zero there), and lines are built in parallel.
  struct Local {
    struct Line {
      int axis;
      double pu, pv;
      int b0, b1;  // breakpoints [b0, b1)
    };
    struct Part {  // the lines one thread built
      std::vector<Line> lines;
      std::vector<double> t, w, slope;  // breakpoint, cumulative weight there, slope after it
    };
    std::vector<Part> parts;
    double scale = 1.0;  // lines each kept line stands for
  };
  /// With `max_lines` > 0, a neighbourhood that would hold more lines keeps an evenly spread
  /// subset (every k-th row and column of each axis' grid, which ones set by `phase`), so a
  /// large sphere costs no more than a small one; its values are then estimates.
  void local(const Spheres& spheres, int i, double reach, Local& out, int max_lines = 0,
             int phase = 0) const;
  /// XOR volume (m^3, up to a constant) with sphere `i` replaced by `s`, which must lie within
  /// the neighbourhood's reach. Differences of two calls are exact changes of the XOR volume
  /// on the cache's rays (without subsampling).
  double local_value(const Local& L, const Sphere& s) const;
  /// local_value of `n` spheres at once (`out[k]` for `s[k]`, the same values to the bit): the
  /// neighbourhood is read once for many trials.
  void local_values(const Local& L, const Sphere* s, int n, double* out) const;

  double shape_volume() const { return shape_volume_; }
  const Moments& shape_moments() const { return shape_moments_; }

 private:
  struct Axis {
    int nu = 0, nv = 0;
    double u0 = 0, v0 = 0, du = 0, dv = 0;
    std::vector<double> pu, pv;        // per line (i * nv + j)
    std::vector<int> first;            // per line: first shape interval, size lines + 1
    std::vector<Interval> shape;       // flattened shape intervals
    std::vector<double> shape_length;  // per line
    double shape_total = 0.0;          // sum of lengths
  };
  Axis axes_[3];
  double shape_volume_ = 0.0;
  Moments shape_moments_;
  int threads_ = 1;
};

}  // namespace clumpkit::detail
