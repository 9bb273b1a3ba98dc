#pragma once
// Shared helpers of the CLI commands: data-folder lookup, output, number formatting.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace clumpkit::cli {

/// The bundled data folder (shapes/, meshes/): $CLUMPKIT_DATA, else the source tree's.
std::filesystem::path data_dir();

/// Resolves a shape argument: an existing path, or a bundled name ("pill_A" -> shapes/pill_A.toml).
std::filesystem::path resolve_shape(const std::string& arg);

/// Resolves a model argument: an existing file, or a bundled model name
/// ("production" -> shapes/models/production.toml). Throws InputError naming `field`.
std::filesystem::path find_model(const std::string& arg, const std::string& field = "--model");

/// Writes JSON to a file (atomically) or to stdout for "-".
void write_json(const nlohmann::json& j, const std::string& target);

/// A warning on stderr when a mesh read with --mesh-units `units` is implausibly large (over
/// 0.5 m across) or small (under 50 µm) for a particle: most CAD and scan files are in
/// millimetres, and the default unit is the metre. `extent` is the largest side of its bounds, m.
void warn_if_mesh_units_suspect(const std::string& file, double extent, const std::string& units);

/// The mesh repairs a command offers (--repair-orientation, --repair-holes): registered once, then
/// merged into a MeshLoadOptions or a ShapeSpec (both have the two fields; what a shape file asks
/// for itself stays on).
struct MeshRepairFlags {
  bool orientation = false, holes = false;
  /// Adds the two flags to `command`; `scope` starts their help ("edt/optimal: ...").
  void add_to(CLI::App* command, const std::string& scope);
  template <class Options>
  void apply(Options& o) const {
    o.repair_orientation = o.repair_orientation || orientation;
    o.repair_holes = o.repair_holes || holes;
  }
};

/// Records the repairs `o` asks for in a clump template's `source`, so that `clumpkit error`
/// re-reads the mesh the same way.
template <class Options>
void record_mesh_repairs(const Options& o, nlohmann::json& source) {
  if (o.repair_orientation) source["repair_orientation"] = true;
  if (o.repair_holes) source["repair_holes"] = true;
}

/// A command registers itself on the app; the returned callback runs it and returns the exit code.
using Runner = std::function<int()>;
struct Command {
  CLI::App* app;
  Runner run;
};

}  // namespace clumpkit::cli

namespace clumpkit::cli {

/// Self-registration of commands: each cmd_<name>.cpp defines one static Registration.
/// `order` sorts the subcommands in --help (pipeline order).
struct Registration {
  using Setup = Command (*)(CLI::App& parent);
  Registration(int order, Setup setup);
};
std::vector<std::pair<int, Registration::Setup>>& registry();

}  // namespace clumpkit::cli
