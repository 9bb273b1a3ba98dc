#pragma once
/// Clump templates out to the DEM codes people use. Every format is written in the clump's
/// centroid-principal frame (the template's own frame, metres) and records the transform back to
/// the source shape's frame (p_source = R p_template + t) and the sphere union's mass, volume,
/// density and principal moments, in SI units.
///
/// An export is a set of files written into one output folder. Rendering (text only) is separate
/// from writing (all files staged as temporaries, renamed into place only when every one of them
/// was written), so a failed export leaves no partial output.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "clumpkit/geometry/clump_template.hpp"

namespace clumpkit {

struct ExportSettings {
  /// Base of the file names ("pill_A12" -> pill_A12.mol ...). Empty: the template's name, else
  /// "clump". Must be a plain file name (no folder separators).
  std::string base_name;
  /// LIGGGHTS: multisphere template type (`type` keyword, consecutive from 1) and atom type;
  /// LAMMPS: the atom type of the molecule's spheres.
  int template_type = 1;
  int atom_type = 1;
};

/// One output file: a name relative to the output folder, and its full content.
struct ExportFile {
  std::string name;
  std::string content;
};

/// A registered format: name (the --format value), a one-line description of what it writes, and
/// its renderer.
struct Exporter {
  std::string_view name;
  std::string_view description;
  std::vector<ExportFile> (*render)(const ClumpTemplate& clump, const ExportSettings& settings);
};

/// All formats, in the order of SPEC §5: liggghts, lammps, edem, yade, mercurydpm, deme, vtk.
const std::vector<Exporter>& exporters();

/// nullptr for an unknown name.
const Exporter* find_exporter(std::string_view name);

/// The comma-separated list of format names, for messages and --help.
std::string exporter_names();

/// Renders a template in a format. Throws InputError with field "--format" naming the known
/// formats for an unknown one, and InputError for a template a format cannot hold.
std::vector<ExportFile> render_export(const ClumpTemplate& clump, std::string_view format,
                                      const ExportSettings& settings = {});

/// Writes the files into `folder` (created if missing; its parent must exist), all or nothing:
/// each file is staged as a temporary beside its target and the temporaries are renamed only
/// after all were written. Returns the written paths. Throws InputError naming the path on any
/// failure, after removing the temporaries (and the folder, if this call created it).
std::vector<std::filesystem::path> write_export(const std::vector<ExportFile>& files,
                                                const std::filesystem::path& folder);

/// render_export + write_export.
std::vector<std::filesystem::path> export_clump(const ClumpTemplate& clump, std::string_view format,
                                                const std::filesystem::path& folder,
                                                const ExportSettings& settings = {});

/// The file base name used for `settings` and `clump` (see ExportSettings::base_name).
std::string export_base_name(const ClumpTemplate& clump, const ExportSettings& settings);

}  // namespace clumpkit
