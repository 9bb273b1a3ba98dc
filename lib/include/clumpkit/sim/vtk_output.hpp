#pragma once
/// VTK XML PolyData (.vtp) for ParaView: sub-spheres as points (use a Glyph filter with the
/// `radius` array, scale by scalar, factor 2 for diameter) and walls as triangle surfaces, plus
/// .pvd collections indexing the frames by simulated time.
#include <filesystem>
#include <string>
#include <vector>

#include "clumpkit/dem/world.hpp"

namespace clumpkit::sim {

/// Sub-spheres with `radius` (m), `clump_id`, `clump_type` and `velocity` (m/s) point arrays.
std::string particles_vtp(const dem::World& world);
/// All walls' current triangles with a `wall_id` cell array.
std::string walls_vtp(const dem::World& world);
/// One wall's current triangles (its `wall_id` on every cell).
std::string wall_vtp(const dem::World& world, int wall);
/// A ParaView collection of (time, file) frames.
std::string pvd(const std::vector<std::pair<double, std::string>>& frames);

}  // namespace clumpkit::sim
