// The EDT baseline: the Euclidean-map greedy of CLUMP and MSS, kept faithful so that comparisons
// with the optimiser are fair: same distance field, same tolerance and minimum radius.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "clumpkit/core/error.hpp"
#include "clumpkit/fill/fill_problem.hpp"
#include "fill_context.hpp"

namespace clumpkit {

FillResult edt_fill(const FillShape& shape, const FillOptions& options) {
  const detail::FillContext ctx(shape, options);
  const detail::DistanceGrid& g = ctx.grid;
  // Candidates: inside voxels, largest distance first.
  std::vector<std::int64_t> cand;
  for (std::int64_t i = 0; i < g.size(); ++i)
    if (g.inside[i] && ctx.tolerance - g.sdf[i] >= options.min_radius) cand.push_back(i);
  double rmax = 0.0;
  for (std::int64_t i = 0; i < g.size(); ++i)
    if (g.inside[i]) rmax = std::max(rmax, ctx.tolerance - static_cast<double>(g.sdf[i]));
  if (cand.empty())
    throw InputError(shape.where, "--min-radius",
                     fmt::format("{:.4g} mm is larger than the largest sphere that fits in the "
                                 "shape ({:.4g} mm with the tolerance)",
                                 options.min_radius * 1e3, rmax * 1e3));
  std::stable_sort(cand.begin(), cand.end(),
                   [&](std::int64_t a, std::int64_t b) { return g.sdf[a] < g.sdf[b]; });
  std::vector<std::uint8_t> covered(g.size(), 0);
  const int budget = options.spheres > 0 ? options.spheres : options.max_spheres;
  FillResult res;
  res.tolerance = ctx.tolerance;
  size_t next = 0;
  nlohmann::json history = nlohmann::json::array();
  detail::FillContext::Errors err{1.0, 1.0};
  while (static_cast<int>(res.spheres.size()) < budget) {
    while (next < cand.size() && covered[cand[next]]) ++next;
    if (next == cand.size()) break;  // every inside voxel is covered
    const std::int64_t v = cand[next];
    const int i = static_cast<int>(v % g.n.x()), j = static_cast<int>((v / g.n.x()) % g.n.y()),
              k = static_cast<int>(v / (static_cast<std::int64_t>(g.n.x()) * g.n.y()));
    Sphere s;
    s.center = g.center(i, j, k);
    s.radius = ctx.max_radius(s.center);
    if (s.radius < options.min_radius || s.radius <= 0) {
      covered[v] = 1;
      continue;
    }
    res.spheres.push_back(s);
    // Mark the voxels inside the new sphere as covered.
    const int reach = static_cast<int>(std::ceil(s.radius / g.h));
    for (int kk = std::max(0, k - reach); kk <= std::min(g.n.z() - 1, k + reach); ++kk)
      for (int jj = std::max(0, j - reach); jj <= std::min(g.n.y() - 1, j + reach); ++jj)
        for (int ii = std::max(0, i - reach); ii <= std::min(g.n.x() - 1, i + reach); ++ii)
          if ((g.center(ii, jj, kk) - s.center).squaredNorm() <= s.radius * s.radius)
            covered[g.index(ii, jj, kk)] = 1;
    if (options.max_error > 0 || static_cast<int>(res.spheres.size()) == budget) {
      Spheres tmp = res.spheres;
      ctx.enforce_containment(tmp);
      err = ctx.errors(tmp);
      history.push_back({{"spheres", res.spheres.size()}, {"error", err.metric}});
      if (options.max_error > 0 && err.metric <= options.max_error) break;
    }
  }
  ctx.enforce_containment(res.spheres);
  err = ctx.errors(res.spheres);
  res.error = err.metric;
  res.target_reached = options.max_error <= 0 || err.metric <= options.max_error;
  res.report = {{"algorithm",
                 "greedy largest inscribed sphere on the voxel distance map, "
                 "covered voxels removed"},
                {"grid_cell", g.h},
                {"symmetric_difference", err.symmetric_difference},
                {"uncovered_candidates_left", next < cand.size()}};
  if (options.max_error > 0) res.report["history"] = history;
  return res;
}

}  // namespace clumpkit
