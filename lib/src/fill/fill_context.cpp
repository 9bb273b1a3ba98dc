#include "fill_context.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "clumpkit/core/error.hpp"
#include "clumpkit/geometry/mass_properties.hpp"

namespace clumpkit::detail {

std::vector<Eigen::Vector3d> fibonacci_sphere(int n) {
  std::vector<Eigen::Vector3d> p(n);
  const double ga = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(std::max(0.0, 1.0 - z * z));
    p[i] = {r * std::cos(ga * i), r * std::sin(ga * i), z};
  }
  return p;
}

double inertia_error(const Moments& s, const Moments& u) {
  if (u.m0 <= 0) return 1.0;
  const MassProperties ms = mass_properties(s, 1.0), mu = mass_properties(u, 1.0);
  double e = 0.0;
  for (int k = 0; k < 3; ++k)
    e = std::max(
        e, std::abs(mu.principal_moments[k] - ms.principal_moments[k]) / ms.principal_moments[k]);
  return e;
}

FillContext::FillContext(const FillShape& s, const FillOptions& o) : shape(s), options(o) {
  if (!shape.solid) throw std::invalid_argument("FillContext: no solid");
  validate_fill_options(o);
  grid = build_distance_grid(*shape.solid, o.grid, o.threads);
  const double cell = grid.h * grid.h * grid.h;
  std::int64_t in = 0;
  for (auto f : grid.inside) in += f;
  if (in == 0)
    throw InputError(shape.where, "",
                     "the shape has no inside at this grid resolution (open "
                     "mesh, inverted normals or far too thin?)");
  size = std::cbrt(6.0 * in * cell / std::numbers::pi);
  tolerance = o.tolerance >= 0 ? o.tolerance : 0.01 * size;
  Eigen::AlignedBox3d box = shape.solid->bounds();
  const double pad = 2.0 * tolerance + 1e-3 * size;
  box.min().array() -= pad;
  box.max().array() += pad;
  cache = std::make_unique<RayCache>(*shape.solid, box, o.rays, o.seed, o.threads);
}

double FillContext::distance(const Eigen::Vector3d& p) const {
  return shape.exact_distance ? shape.exact_distance(p) : grid.sample(p);
}

Eigen::Vector3d FillContext::distance_gradient(const Eigen::Vector3d& p) const {
  const double e = shape.exact_distance ? 1e-4 * size : 0.5 * grid.h;
  Eigen::Vector3d g;
  for (int a = 0; a < 3; ++a) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d[a] = e;
    g[a] = (distance(p + d) - distance(p - d)) / (2.0 * e);
  }
  return g;
}

bool FillContext::inside(const Eigen::Vector3d& p) const {
  // Ray intervals are exact for every solid and cheaper than a distance query on meshes.
  thread_local IntervalList list;
  shape.solid->intervals(p, 0, list);
  for (const Interval& iv : list)
    if (p.x() > iv.t0 && p.x() < iv.t1) return true;
  return false;
}

FillContext::Errors FillContext::errors(const Spheres& spheres) const {
  const bool need_m = options.metric == FillMetric::Inertia;
  const RayCache::Eval e = cache->evaluate(spheres, need_m);
  Errors r;
  const double vs = cache->shape_volume();
  r.symmetric_difference = e.xor_volume / vs;
  switch (options.metric) {
    case FillMetric::SymmetricDifference:
      r.metric = r.symmetric_difference;
      break;
    case FillMetric::Volume:
      r.metric = std::abs(e.union_volume - vs) / vs;
      break;
    case FillMetric::Inertia:
      r.metric = inertia_error(cache->shape_moments(), e.union_moments);
      break;
  }
  return r;
}

double FillContext::objective(const Spheres& spheres, std::vector<double>* removal_cost) const {
  const double vs = cache->shape_volume();
  const double f = cache->evaluate(spheres, false, removal_cost).xor_volume / vs;
  if (removal_cost)
    for (double& c : *removal_cost) c /= vs;
  return f;
}

void FillContext::enforce_containment(Spheres& spheres) const {
  if (shape.exact_distance) return;
  static const std::vector<Eigen::Vector3d> dirs = fibonacci_sphere(256);
  for (Sphere& s : spheres) {
    auto ok = [&](double r) {
      const double core = r - tolerance;
      if (core <= 0) return true;
      if (!inside(s.center)) return false;
      for (const auto& d : dirs)
        if (!inside(s.center + core * d)) return false;
      return true;
    };
    if (ok(s.radius)) continue;
    double lo = 0.0, hi = s.radius;
    for (int it = 0; it < 30; ++it) {
      const double mid = 0.5 * (lo + hi);
      (ok(mid) ? lo : hi) = mid;
    }
    s.radius = std::max(lo, 1e-9 * size);
  }
}

}  // namespace clumpkit::detail
