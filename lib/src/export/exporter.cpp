#include "clumpkit/export/exporter.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <system_error>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "format_text.hpp"

namespace clumpkit {

namespace fs = std::filesystem;
using namespace export_detail;

const std::vector<Exporter>& exporters() {
  static const std::vector<Exporter> list = {
      {"liggghts",
       "LIGGGHTS 3.8: BASE_spheres.txt ('x y z r' per sphere) + BASE.liggghts (fix "
       "particletemplate/multisphere snippet with union mass and inertia_tensor)",
       render_liggghts},
      {"lammps",
       "LAMMPS molecule file BASE.mol (mass/com/inertia header; Coords, Types, Diameters, "
       "Masses) for fix rigid/small",
       render_lammps},
      {"edem", "EDEM: BASE_spheres.csv (x,y,z,radius) + BASE_mass.csv (mass properties)",
       render_edem},
      {"yade", "Yade: BASE_yade.py with clumpTemplate(relRadii, relPositions) and a helper",
       render_yade},
      {"mercurydpm",
       "MercuryDPM: BASE/Clump.txt, Mass.txt, TOI.txt, PD.txt (+ BASE/clumpkit_frame.txt)",
       render_mercurydpm},
      {"deme",
       "DEM-Engine: BASE_deme.csv (x,y,z,r) + BASE_deme_mass.csv (mass, principal moments for "
       "LoadClumpType)",
       render_deme},
      {"vtk", "VTK: BASE.vtp PolyData of sphere centres with a 'radius' point array (ParaView)",
       render_vtk},
  };
  return list;
}

const Exporter* find_exporter(std::string_view name) {
  for (const Exporter& e : exporters())
    if (e.name == name) return &e;
  return nullptr;
}

std::string exporter_names() {
  std::string out;
  for (const Exporter& e : exporters()) {
    if (!out.empty()) out += ", ";
    out += e.name;
  }
  return out;
}

std::string export_base_name(const ClumpTemplate& clump, const ExportSettings& settings) {
  std::string base = settings.base_name;
  if (base.empty()) base = clump.name;
  if (base.empty()) base = "clump";
  return base;
}

std::vector<ExportFile> render_export(const ClumpTemplate& clump, std::string_view format,
                                      const ExportSettings& settings) {
  const Exporter* e = find_exporter(format);
  if (!e)
    throw InputError("", "--format",
                     fmt::format("unknown format '{}' (known: {})", format, exporter_names()));
  const std::string base = export_base_name(clump, settings);
  if (base.find('/') != std::string::npos || base == "." || base == "..")
    throw InputError("", "--name", fmt::format("'{}' is not a plain file name", base));
  if (settings.template_type < 1 || settings.atom_type < 1)
    throw InputError("", "--type", "template and atom types start at 1");
  validate_spheres(clump.spheres, clump.name.empty() ? "clump" : clump.name);
  return e->render(clump, settings);
}

namespace {

// Removes what a failed export staged; never throws.
void cleanup(const std::vector<fs::path>& temps, const std::vector<fs::path>& dirs) {
  std::error_code ec;
  for (const fs::path& t : temps) fs::remove(t, ec);
  for (auto it = dirs.rbegin(); it != dirs.rend(); ++it) fs::remove(*it, ec);  // only if empty
}

}  // namespace

std::vector<fs::path> write_export(const std::vector<ExportFile>& files,
                                   const fs::path& folder_arg) {
  std::error_code ec;
  if (folder_arg.empty()) throw InputError("", "-o", "empty output folder");
  // "out/" names the folder "out" (its parent is "."), as a shell user means it.
  fs::path folder = folder_arg;
  while (!folder.has_filename() && folder.has_relative_path()) folder = folder.parent_path();
  if (fs::exists(folder, ec) && !fs::is_directory(folder, ec))
    throw InputError(folder.string(), "-o", "exists and is not a folder");
  // Check every target before touching the disk.
  for (const ExportFile& f : files) {
    const fs::path target = folder / f.name;
    if (fs::is_directory(target, ec))
      throw InputError(target.string(), "-o", "a folder is in the way of this output file");
  }
  std::vector<fs::path> made_dirs, temps, finals;
  auto make_dir = [&](const fs::path& d) {
    if (fs::is_directory(d, ec)) return;
    const fs::path parent = d.parent_path().empty() ? fs::path(".") : d.parent_path();
    if (!fs::is_directory(parent, ec))
      throw InputError(d.string(), "-o", "parent folder '" + parent.string() + "' does not exist");
    if (!fs::create_directory(d, ec) || ec)
      throw InputError(d.string(), "-o", "cannot create folder: " + ec.message());
    made_dirs.push_back(d);
  };
  try {
    make_dir(folder);
    for (const ExportFile& f : files) {
      const fs::path target = folder / f.name;
      make_dir(target.parent_path());
      const fs::path tmp =
          target.parent_path() /
          fmt::format(".{}.clumpkit-staged{}", target.filename().string(), ::getpid());
      write_file_atomic(tmp, f.content);
      temps.push_back(tmp);
      finals.push_back(target);
    }
  } catch (...) {
    cleanup(temps, made_dirs);
    throw;
  }
  // All content is on disk; renames within one folder do not fail short of a vanished folder.
  for (size_t i = 0; i < temps.size(); ++i) {
    if (std::rename(temps[i].c_str(), finals[i].c_str()) != 0) {
      const std::string why = std::error_code(errno, std::generic_category()).message();
      cleanup(std::vector<fs::path>(temps.begin() + static_cast<long>(i), temps.end()), {});
      throw InputError(finals[i].string(), "-o", "cannot rename into place: " + why);
    }
  }
  return finals;
}

std::vector<fs::path> export_clump(const ClumpTemplate& clump, std::string_view format,
                                   const fs::path& folder, const ExportSettings& settings) {
  return write_export(render_export(clump, format, settings), folder);
}

}  // namespace clumpkit
