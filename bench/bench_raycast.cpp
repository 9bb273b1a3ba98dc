// Ray-sampling speed: lines per second through a 10 000-triangle mesh and through a 12-sphere
// union, and the whole shape-error analysis of the paper's 12-sphere pill A against a
// 10 000-triangle cylinder mesh, with the volume accuracy each ray budget reaches.
//   bench_raycast --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>

#include "clumpkit/geometry/sphere_union.hpp"
#include "clumpkit/mesh_io/primitive_meshes.hpp"
#include "clumpkit/raycast/mesh_solid.hpp"
#include "clumpkit/raycast/shape_error.hpp"

namespace {

using namespace clumpkit;
constexpr double kD = 0.006, kH = 0.0054;

// 4 n = 10 000 triangles: 2 n on the side, n on each cap.
const MeshSolid& cylinder10k() {
  static const MeshSolid solid(cylinder_mesh(kD, kH, 2500, 1));
  return solid;
}

Spheres pill_a12() {
  const double r = kH / 3;
  Spheres s;
  for (double z : {kH / 6, -kH / 6})
    for (int k = 0; k < 6; ++k)
      s.push_back({Eigen::Vector3d((kD / 2 - r) * std::cos(k * std::numbers::pi / 3),
                                   (kD / 2 - r) * std::sin(k * std::numbers::pi / 3), z),
                   r});
  return s;
}

// Lines through a solid, one thread, over a 3-axis jittered grid.
void lines(benchmark::State& state, const RaySolid& solid) {
  const Eigen::AlignedBox3d box = solid.bounds();
  SplitMix rng(1);
  IntervalList out;
  std::int64_t n = 0;
  for (auto _ : state) {
    for (int k = 0; k < 1000; ++k) {
      const int axis = k % 3;
      Eigen::Vector3d o;
      for (int c = 0; c < 3; ++c) o[c] = box.min()[c] + rng.uniform() * box.sizes()[c];
      solid.intervals(o, axis, out);
      benchmark::DoNotOptimize(out.data());
    }
    n += 1000;
  }
  state.counters["lines/s"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsRate);
}

void BM_MeshLines10k(benchmark::State& state) {
  lines(state, cylinder10k());
}
BENCHMARK(BM_MeshLines10k)->Unit(benchmark::kMillisecond);

void BM_UnionLines12(benchmark::State& state) {
  const SphereUnion u(pill_a12());
  lines(state, u);
}
BENCHMARK(BM_UnionLines12)->Unit(benchmark::kMillisecond);

// The full analysis (4 channels, surface distances) on all cores; Arg = total rays.
void BM_PillErrorVsMesh10k(benchmark::State& state) {
  ShapeErrorOptions o;
  o.sampling.rays = state.range(0);
  o.density = 1380;
  ShapeError e;
  for (auto _ : state) e = shape_error(cylinder10k(), pill_a12(), o);
  const double exact = polyhedron_moments(cylinder10k().mesh()).m0;
  state.counters["vol_ci95_rel"] = e.shape_ci.volume / e.shape.volume;
  state.counters["vol_err_rel"] = std::abs(e.shape.volume / exact - 1);
  state.counters["xor_ci95_rel"] = e.sym_diff_rel.ci95;
  state.counters["rays/s"] = benchmark::Counter(static_cast<double>(state.range(0)),
                                                benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_PillErrorVsMesh10k)
    ->Arg(100'000)
    ->Arg(300'000)
    ->Arg(1'500'000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
