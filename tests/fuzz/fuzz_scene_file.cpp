// Fuzz target: scene files for `clumpkit sim` (docs/scene_format.md) through load_scene, then
// dem::World::create, which validates the physics (as `clumpkit sim` does before running). The
// scene is written to a per-process folder under /dev/shm (load_scene reads a path; relative
// templates and meshes resolve there (a4.json and hopper.stl are put there), bundled shapes and
// materials come from the source tree).
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "clumpkit/dem/world.hpp"
#include "clumpkit/sim/scene.hpp"
#include "fuzz_util.hpp"

namespace {

namespace fs = std::filesystem;

fs::path scene_path() {
  const fs::path base =
      fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
  const fs::path dir = base / ("clumpkit_fuzz_scene_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  // Files the seed scenes refer to by relative path: a clump template and an open wall mesh.
  const fs::path src(CLUMPKIT_SOURCE_DIR);
  const auto over = fs::copy_options::overwrite_existing;
  fs::copy_file(src / "tests/fuzz/corpus/clump_json/A4.json", dir / "a4.json", over);
  fs::copy_file(src / "meshes/rigs/hopper.stl", dir / "hopper.stl", over);
  return dir / "scene.toml";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace clumpkit;
  // A clump type given as shape + spheres is filled by the paper's rule with 1.5 M rays for its
  // mass properties (seconds under ASan): fill and shapes are fuzzed by shape_file, so such
  // inputs are skipped here and the seeds use clump templates.
  const std::string text = fuzz::as_text(data, size);
  if (text.find("spheres") != std::string::npos) return 0;
  static const fs::path path = scene_path();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  fuzz::input_errors_only([&] {
    const sim::Scene s = sim::load_scene(path, CLUMPKIT_SOURCE_DIR);
    CLUMPKIT_FUZZ_CHECK(std::isfinite(s.until) && s.until > 0.0, "until");
    CLUMPKIT_FUZZ_CHECK(std::isfinite(s.output.every) && s.output.every > 0.0, "output.every");
    CLUMPKIT_FUZZ_CHECK(!s.world.clump_types.empty(), "accepted a scene without clump types");
    const dem::World w = dem::World::create(s.world);
    CLUMPKIT_FUZZ_CHECK(std::isfinite(w.dt()) && w.dt() > 0.0, "time step");
  });
  return 0;
}
