#pragma once
/// Writes a particle model back as a model file (the format of shapes/models/*.toml), with file
/// paths made relative to where it is written. Used by `clumpkit diagnose --apply`.
#include <filesystem>
#include <string>

#include "clumpkit/rigs/model.hpp"

namespace clumpkit::calibrate {

std::string format_model(const ParticleModel& model, const std::filesystem::path& target,
                         const std::string& note = "");

}  // namespace clumpkit::calibrate
