#pragma once
/// Scene files: a human-editable TOML description of a DEM run (clump types, materials, walls and
/// their motions, factories, time and output settings) for `clumpkit sim`. The format is
/// documented in docs/scene_format.md; every dimensioned value carries its unit.
#include <filesystem>
#include <string>
#include <vector>

#include "clumpkit/core/toml_doc.hpp"
#include "clumpkit/dem/world.hpp"

namespace clumpkit::sim {

/// A region whose contained mass (clumps by centre of mass) is recorded in the time series.
struct NamedRegion {
  std::string name;
  dem::Region region;
};

struct OutputSettings {
  double every = 0.0;  ///< s between output frames; 0 = until / 50
  bool vtk = true;     ///< particles and walls as VTK PolyData series (ParaView)
  double checkpoint_minutes =
      5.0;  ///< wall-clock minutes between checkpoints (also on SIGINT/TERM)
};

struct Scene {
  std::filesystem::path path;
  dem::WorldSettings world;
  double until = 0.0;  ///< s, simulated end time
  OutputSettings output;
  std::vector<NamedRegion> regions;
};

/// Loads and validates a scene (the World itself validates the physics on creation). Relative
/// file paths (templates, meshes, materials) are resolved against the scene file's folder.
/// Throws InputError naming the file, line and key.
Scene load_scene(const std::filesystem::path& path, const std::filesystem::path& data_dir);

/// Parses a region table at `key` (kind = "box" with min/max, or "cylinder" with base, radius,
/// height). Shared with the rigs.
dem::Region parse_region(const TomlDoc& doc, const std::string& key);

}  // namespace clumpkit::sim
