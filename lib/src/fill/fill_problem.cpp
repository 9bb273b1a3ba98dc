#include "clumpkit/fill/fill_problem.hpp"

#include <fmt/format.h>

#include <cmath>

#include "clumpkit/core/error.hpp"
#include "clumpkit/geometry/sphere_union.hpp"
#include "fill_context.hpp"

namespace clumpkit {

const char* to_string(FillMetric m) {
  switch (m) {
    case FillMetric::SymmetricDifference:
      return "symmetric_difference";
    case FillMetric::Volume:
      return "volume";
    case FillMetric::Inertia:
      return "inertia";
  }
  return "?";
}

FillMetric parse_fill_metric(const std::string& s) {
  if (s == "symmetric_difference") return FillMetric::SymmetricDifference;
  if (s == "volume") return FillMetric::Volume;
  if (s == "inertia") return FillMetric::Inertia;
  throw InputError("", "--metric",
                   "'" + s + "' is not one of volume, symmetric_difference, inertia");
}

void validate_fill_options(const FillOptions& o) {
  if (o.spheres < 0) throw InputError("", "--spheres", "must be positive");
  if (o.spheres == 0 && o.max_error <= 0)
    throw InputError("", "--spheres",
                     "give a sphere budget (--spheres N) or an error target "
                     "(--max-error E)");
  if (o.max_error < 0 || o.max_error >= 1 || !std::isfinite(o.max_error))
    throw InputError(
        "", "--max-error",
        fmt::format("{} is not a relative error in (0, 1) (e.g. 0.05 for 5 %)", o.max_error));
  if (o.min_radius < 0 || !std::isfinite(o.min_radius))
    throw InputError("", "--min-radius", "must be zero or positive (metres)");
  if (!std::isfinite(o.tolerance)) throw InputError("", "--tolerance", "must be finite");
  if (o.max_spheres < 1) throw InputError("", "--max-spheres", "must be at least 1");
  if (o.spheres > 5000) throw InputError("", "--spheres", "at most 5000 spheres");
  if (o.grid < 16 || o.grid > 400) throw InputError("", "--grid", "must be in [16, 400] cells");
  if (o.rays < 3000) throw InputError("", "--rays", "at least 3000 rays");
}

double FillMeasurement::value(FillMetric m) const {
  switch (m) {
    case FillMetric::SymmetricDifference:
      return symmetric_difference.value;
    case FillMetric::Volume:
      return volume.value;
    case FillMetric::Inertia:
      return inertia.value;
  }
  return 0.0;
}

nlohmann::json FillMeasurement::to_json() const {
  auto e = [](const Estimate& x) { return nlohmann::json{{"value", x.value}, {"ci95", x.ci95}}; };
  return {{"symmetric_difference", e(symmetric_difference)},
          {"volume", e(volume)},
          {"inertia", e(inertia)},
          {"shape_volume", shape_volume},
          {"units", "relative (1): |S xor U|/|S|, |V_U - V_S|/V_S, max_k |I_k(U) - I_k(S)|/I_k(S)"},
          {"measured_by", "ray sampling, independent of the fill's own rays"}};
}

FillMeasurement measure_fill(const FillShape& shape, const Spheres& spheres,
                             const RaySamplingOptions& sampling) {
  const SphereUnion u(spheres);
  Eigen::AlignedBox3d box = shape.solid->bounds();
  box.extend(u.bounds());
  auto r = integrate_rays(
      box, 3,
      [&](const Eigen::Vector3d& o, int axis, std::vector<IntervalList>& ch) {
        shape.solid->intervals(o, axis, ch[0]);
        u.intervals(o, axis, ch[1]);
        ch[2] = xor_intervals(ch[0], ch[1]);
      },
      sampling);
  std::vector<double> sd, vol, in;
  FillMeasurement m;
  double vs_mean = 0.0;
  for (size_t k = 0; k < r[0].size(); ++k) {
    const double vs = r[0][k].m0;
    vs_mean += vs / static_cast<double>(r[0].size());
    sd.push_back(r[2][k].m0 / vs);
    vol.push_back(std::abs(r[1][k].m0 - vs) / vs);
    in.push_back(detail::inertia_error(r[0][k], r[1][k]));
  }
  m.symmetric_difference = estimate(sd);
  m.volume = estimate(vol);
  m.inertia = estimate(in);
  m.shape_volume = vs_mean;
  return m;
}

ClumpTemplate fill_template(const std::string& method, const FillOptions& o, const FillResult& r,
                            const FillMeasurement& measured, double density,
                            const RaySamplingOptions& sampling) {
  ClumpTemplate c = make_clump_template(r.spheres, density, sampling);
  c.method = {{"name", method},
              {"spheres", r.spheres.size()},
              {"sphere_budget", o.spheres},
              {"metric", to_string(o.metric)},
              {"tolerance", r.tolerance},
              {"min_radius", o.min_radius},
              {"grid_cells", o.grid},
              {"objective_rays", o.rays},
              {"seed", o.seed},
              {"error_on_objective_rays", r.error},
              {"report", r.report}};
  if (o.max_error > 0) {
    c.method["target_error"] = o.max_error;
    c.method["target_reached"] = r.target_reached;
  }
  c.error = measured.to_json();
  return c;
}

FillShape fill_shape_with_surface_distance(
    std::shared_ptr<const RaySolid> solid,
    std::function<double(const Eigen::Vector3d&)> surface_distance, std::string where) {
  FillShape s{solid, nullptr, std::move(where)};
  s.exact_distance = [solid, surface_distance](const Eigen::Vector3d& p) {
    thread_local IntervalList list;
    solid->intervals(p, 0, list);
    bool in = false;
    for (const Interval& iv : list) in = in || (p.x() > iv.t0 && p.x() < iv.t1);
    const double d = surface_distance(p);
    return in ? -d : d;
  };
  return s;
}

}  // namespace clumpkit
