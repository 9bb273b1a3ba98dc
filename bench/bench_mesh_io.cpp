// load_mesh on one closed mesh written in each format it reads: STL (binary) and OBJ through
// assimp, PLY (ASCII and binary) and OFF through clumpkit's own readers. Reading, welding and
// validation are timed (the self-intersection check is off: it does not depend on the format).
//   cmake --build build --target bench_mesh_io && build/bench/bench_mesh_io
//   (--benchmark_filter=Ply, --benchmark_repetitions=5 ...; CLUMPKIT_BENCH_SUBDIV=N sets the
//   icosphere's subdivisions, default 7: 327 680 triangles)
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "clumpkit/mesh_io/load_mesh.hpp"
#include "clumpkit/mesh_io/primitive_meshes.hpp"
#include "clumpkit/mesh_io/write_mesh.hpp"

namespace {

namespace fs = std::filesystem;
using clumpkit::TriangleMesh;

const TriangleMesh& sphere() {
  static const TriangleMesh m = [] {
    const char* s = std::getenv("CLUMPKIT_BENCH_SUBDIV");
    return clumpkit::icosphere_mesh(0.005, s ? std::atoi(s) : 7);
  }();
  return m;
}

fs::path folder() {
  static const fs::path d = [] {
    const fs::path p = fs::temp_directory_path() / "clumpkit_bench_mesh_io";
    fs::create_directories(p);
    return p;
  }();
  return d;
}

std::string header(const TriangleMesh& m, const char* format) {
  return std::string("ply\nformat ") + format + " 1.0\nelement vertex " +
         std::to_string(m.vertices.size()) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
         std::to_string(m.triangles.size()) +
         "\nproperty list uchar int vertex_indices\nend_header\n";
}

// The sphere in `ext`'s format (written once per run).
fs::path file(const std::string& ext) {
  const TriangleMesh& m = sphere();
  const fs::path p = folder() / ("sphere" + ext);
  if (fs::exists(p)) fs::remove(p);
  if (ext == ".stl") {
    clumpkit::write_stl(m, p);
  } else if (ext == ".obj") {
    clumpkit::write_obj(m, p);
  } else if (ext == ".off" || ext == "_ascii.ply") {
    std::ofstream out(p);
    out.precision(9);
    if (ext == ".off")
      out << "OFF\n" << m.vertices.size() << ' ' << m.triangles.size() << " 0\n";
    else
      out << header(m, "ascii");
    for (const auto& v : m.vertices) out << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
    for (const auto& t : m.triangles) out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  } else {  // binary little-endian PLY (the host's order on x86 and arm64)
    std::ofstream out(p, std::ios::binary);
    out << header(m, "binary_little_endian");
    for (const auto& v : m.vertices)
      for (int k = 0; k < 3; ++k) {
        const float x = static_cast<float>(v[k]);
        out.write(reinterpret_cast<const char*>(&x), 4);
      }
    for (const auto& t : m.triangles) {
      out.put(3);
      for (int k = 0; k < 3; ++k) {
        const std::int32_t i = t[k];
        out.write(reinterpret_cast<const char*>(&i), 4);
      }
    }
  }
  return p;
}

void load(benchmark::State& state, const std::string& ext) {
  const fs::path p = file(ext);
  clumpkit::MeshLoadOptions o;
  o.check_self_intersections = false;
  std::size_t tris = 0;
  for (auto _ : state) {
    const TriangleMesh m = clumpkit::load_mesh(p, o);
    tris = m.triangles.size();
    benchmark::DoNotOptimize(tris);
  }
  state.counters["triangles"] = static_cast<double>(tris);
  state.counters["MB"] = static_cast<double>(fs::file_size(p)) / 1e6;
  state.counters["triangles/s"] =
      benchmark::Counter(static_cast<double>(tris), benchmark::Counter::kIsIterationInvariantRate);
}

BENCHMARK_CAPTURE(load, StlBinary_assimp, std::string(".stl"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(load, Obj_assimp, std::string(".obj"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(load, PlyAscii, std::string("_ascii.ply"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(load, PlyBinary, std::string("_binary.ply"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(load, Off, std::string(".off"))->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
