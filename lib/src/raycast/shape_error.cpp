#include "clumpkit/raycast/shape_error.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "clumpkit/core/error.hpp"
#include "clumpkit/raycast/analytic_surfaces.hpp"

namespace clumpkit {

namespace {

enum Channel { kShape = 0, kClump = 1, kXor = 2, kAnd = 3, kChannels = 4 };

struct DirectedDistance {
  double max = 0.0, mean = 0.0;
};

// Distances from points on one surface to the other surface, in parallel; summed in a fixed
// order so the result does not depend on the thread count.
DirectedDistance directed(const std::vector<Eigen::Vector3d>& pts, const SurfaceSolid& to,
                          int threads) {
  std::vector<double> d(pts.size());
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads)
  for (std::size_t i = 0; i < pts.size(); ++i) d[i] = to.surface_distance(pts[i]);
  DirectedDistance r;
  for (double x : d) {
    r.max = std::max(r.max, x);
    r.mean += x;
  }
  if (!d.empty()) r.mean /= static_cast<double>(d.size());
  return r;
}

// Relative gap of moment k to the nearest other moment.
double gap(const Eigen::Vector3d& m, int k) {
  double g = std::numeric_limits<double>::infinity();
  for (int j = 0; j < 3; ++j)
    if (j != k) g = std::min(g, std::abs(m[k] - m[j]));
  return g / std::max(1e-300, m.maxCoeff());
}

}  // namespace

ShapeError shape_error(const SurfaceSolid& shape, const Spheres& spheres,
                       const ShapeErrorOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  if (opt.sampling.rays <= 0) throw InputError("", "rays", "must be a positive number of rays");
  if (opt.surface_samples == 0)
    throw InputError("", "surface_samples", "must be a positive number of points");
  if (!(opt.density > 0)) throw InputError("", "density", "must be positive");
  const SphereUnionSurface clump(spheres);  // validates the spheres
  const long long unresolved_before = shape.unresolved_lines();

  Eigen::AlignedBox3d box = shape.bounds();
  box.extend(clump.bounds());
  auto samples = integrate_rays(
      box, kChannels,
      [&](const Eigen::Vector3d& o, int axis, std::vector<IntervalList>& ch) {
        shape.intervals(o, axis, ch[kShape]);
        clump.intervals(o, axis, ch[kClump]);
        ch[kXor] = xor_intervals(ch[kShape], ch[kClump]);
        ch[kAnd] = intersect_intervals(ch[kShape], ch[kClump]);
      },
      opt.sampling);

  ShapeError e;
  e.shape = mass_properties(samples[kShape], opt.density, &e.shape_ci);
  e.clump = mass_properties(samples[kClump], opt.density, &e.clump_ci);
  if (!(e.shape.volume > 0)) throw InputError("", "shape", "the shape encloses no volume");
  e.size = std::cbrt(6.0 * e.shape.volume / std::numbers::pi);

  // Derived figures per replicate, so each gets its own interval.
  const std::size_t nrep = samples[kShape].size();
  std::vector<double> vrel, xvol, xrel, avol, off, offrel;
  std::array<std::vector<double>, 3> mrel;
  for (std::size_t r = 0; r < nrep; ++r) {
    const MassProperties s = mass_properties(samples[kShape][r], opt.density);
    const MassProperties c = mass_properties(samples[kClump][r], opt.density);
    vrel.push_back(c.volume / s.volume - 1.0);
    xvol.push_back(samples[kXor][r].m0);
    xrel.push_back(samples[kXor][r].m0 / s.volume);
    avol.push_back(samples[kAnd][r].m0);
    const double o = (c.center_of_mass - s.center_of_mass).norm();
    off.push_back(o);
    offrel.push_back(o / e.size);
    for (int k = 0; k < 3; ++k)
      mrel[k].push_back(c.principal_moments[k] / s.principal_moments[k] - 1.0);
  }
  e.volume_rel_error = estimate(vrel);
  e.sym_diff_volume = estimate(xvol);
  e.sym_diff_rel = estimate(xrel);
  e.intersection_volume = estimate(avol);
  e.com_offset = estimate(off);
  e.com_offset_rel = estimate(offrel);
  for (int k = 0; k < 3; ++k) e.moments_rel_error[k] = estimate(mrel[k]);

  // Principal axes: compare only axes whose moment stands apart in both solids.
  double worst = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double noise_s = 4.0 * e.shape_ci.principal_moments.maxCoeff() /
                           std::max(1e-300, e.shape.principal_moments.maxCoeff());
    const double noise_c = 4.0 * e.clump_ci.principal_moments.maxCoeff() /
                           std::max(1e-300, e.clump.principal_moments.maxCoeff());
    if (gap(e.shape.principal_moments, k) <= std::max(opt.distinct_moments, noise_s) ||
        gap(e.clump.principal_moments, k) <= std::max(opt.distinct_moments, noise_c))
      continue;
    const double c = std::abs(e.shape.principal_axes.col(k).dot(e.clump.principal_axes.col(k)));
    worst = std::max(worst, std::acos(std::min(1.0, c)) * 180.0 / std::numbers::pi);
    ++e.axes_compared;
  }
  if (e.axes_compared > 0) e.axis_angle_deg = worst;

  const int threads = opt.sampling.threads > 0 ? opt.sampling.threads : omp_get_max_threads();
  const auto on_shape = shape.sample_surface(opt.surface_samples, opt.sampling.seed ^ 0x5A17u);
  // From the union's outer surface: the walls of voids enclosed between spheres are inside the
  // particle and would dominate the maximum (their share is reported).
  std::size_t void_points = 0;
  const auto on_clump =
      clump.sample_outer_surface(opt.surface_samples, opt.sampling.seed ^ 0xC1u, &void_points);
  e.void_wall_fraction =
      static_cast<double>(void_points) / static_cast<double>(void_points + on_clump.size());
  const DirectedDistance a = directed(on_shape, clump, threads);
  const DirectedDistance b = directed(on_clump, shape, threads);
  e.shape_to_clump_max = a.max;
  e.shape_to_clump_mean = a.mean;
  e.clump_to_shape_max = b.max;
  e.clump_to_shape_mean = b.mean;
  e.hausdorff = std::max(a.max, b.max);
  e.mean_surface_distance = 0.5 * (a.mean + b.mean);

  e.spheres = spheres.size();
  e.rays = opt.sampling.rays;
  e.replicates = std::max(2, opt.sampling.replicates);
  e.seed = opt.sampling.seed;
  e.surface_samples = opt.surface_samples;
  e.unresolved_lines = shape.unresolved_lines() - unresolved_before;
  e.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return e;
}

ShapeError record_shape_error(ClumpTemplate& clump, const SurfaceSolid& shape,
                              ShapeErrorOptions options) {
  if (clump.mass.density > 0) options.density = clump.mass.density;
  ShapeError e = shape_error(shape, clump.spheres_in_source_frame(), options);
  clump.error = to_json(e);
  return e;
}

namespace {
using nlohmann::json;
json vec(const Eigen::Vector3d& v) {
  return json::array({v[0], v[1], v[2]});
}
json mat(const Eigen::Matrix3d& m) {
  json a = json::array();
  for (int i = 0; i < 3; ++i) a.push_back(json::array({m(i, 0), m(i, 1), m(i, 2)}));
  return a;
}
}  // namespace

nlohmann::json to_json(const ShapeError& e) {
  json rel = json::array(), relci = json::array();
  for (const Estimate& m : e.moments_rel_error) {
    rel.push_back(m.value);
    relci.push_back(m.ci95);
  }
  return {
      {"units", "SI: m, m^3, kg, kg m^2, deg"},
      {"volume",
       {{"shape", e.shape.volume},
        {"clump", e.clump.volume},
        {"rel_error", e.volume_rel_error.value},
        {"ci95",
         {{"shape", e.shape_ci.volume},
          {"clump", e.clump_ci.volume},
          {"rel_error", e.volume_rel_error.ci95}}}}},
      {"symmetric_difference",
       {{"volume", e.sym_diff_volume.value},
        {"rel", e.sym_diff_rel.value},
        {"ci95", {{"volume", e.sym_diff_volume.ci95}, {"rel", e.sym_diff_rel.ci95}}}}},
      {"intersection",
       {{"volume", e.intersection_volume.value}, {"ci95", e.intersection_volume.ci95}}},
      {"center_of_mass",
       {{"shape", vec(e.shape.center_of_mass)},
        {"clump", vec(e.clump.center_of_mass)},
        {"ci95",
         {{"shape", vec(e.shape_ci.center_of_mass)}, {"clump", vec(e.clump_ci.center_of_mass)}}}}},
      {"center_of_mass_offset",
       {{"abs", e.com_offset.value},
        {"rel_to_size", e.com_offset_rel.value},
        {"size", e.size},
        {"size_basis", "equivalent_sphere_diameter_of_shape"},
        {"ci95", {{"abs", e.com_offset.ci95}, {"rel_to_size", e.com_offset_rel.ci95}}}}},
      {"density", e.shape.density},
      {"mass", {{"shape", e.shape.mass}, {"clump", e.clump.mass}}},
      {"inertia_tensor",
       {{"shape", mat(e.shape.inertia_tensor)}, {"clump", mat(e.clump.inertia_tensor)}}},
      {"principal_moments",
       {{"shape", vec(e.shape.principal_moments)},
        {"clump", vec(e.clump.principal_moments)},
        {"rel_error", rel},
        {"ci95",
         {{"shape", vec(e.shape_ci.principal_moments)},
          {"clump", vec(e.clump_ci.principal_moments)},
          {"rel_error", relci}}}}},
      {"principal_axes",
       {{"shape", mat(e.shape.principal_axes)}, {"clump", mat(e.clump.principal_axes)}}},
      {"axis_angle_deg", e.axis_angle_deg ? json(*e.axis_angle_deg) : json(nullptr)},
      {"axis_angle_axes_compared", e.axes_compared},
      {"hausdorff", e.hausdorff},
      {"mean_surface_distance", e.mean_surface_distance},
      {"surface_distance",
       {{"shape_to_clump", {{"max", e.shape_to_clump_max}, {"mean", e.shape_to_clump_mean}}},
        {"clump_to_shape", {{"max", e.clump_to_shape_max}, {"mean", e.clump_to_shape_mean}}},
        {"samples_per_surface", e.surface_samples},
        {"clump_void_wall_fraction", e.void_wall_fraction}}},
      {"spheres", e.spheres},
      {"rays", e.rays},
      {"replicates", e.replicates},
      {"seed", e.seed},
      {"unresolved_lines", e.unresolved_lines},
      {"seconds", e.seconds},
  };
}

}  // namespace clumpkit
