#include "cli_util.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"

namespace clumpkit::cli {

namespace fs = std::filesystem;

fs::path data_dir() {
  if (const char* env = std::getenv("CLUMPKIT_DATA"); env && *env) return env;
  return CLUMPKIT_DATA_DIR;
}

fs::path resolve_shape(const std::string& arg) {
  std::error_code ec;
  if (fs::exists(arg, ec)) return arg;
  for (const fs::path& cand :
       {data_dir() / "shapes" / (arg + ".toml"), data_dir() / "shapes" / arg})
    if (fs::exists(cand, ec)) return cand;
  throw InputError(
      arg, "",
      "no such shape file (nor a bundled shape in " + (data_dir() / "shapes").string() + ")");
}

fs::path find_model(const std::string& arg, const std::string& field) {
  std::error_code ec;
  if (fs::exists(arg, ec) && fs::is_regular_file(arg, ec)) return arg;
  const fs::path dir = data_dir() / "shapes" / "models";
  for (const fs::path& cand : {dir / (arg + ".toml"), dir / arg})
    if (fs::exists(cand, ec)) return cand;
  std::vector<std::string> names;  // in name order (the directory's order is the file system's)
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().extension() == ".toml") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  std::string known;
  for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
  throw InputError("", field,
                   "unknown model '" + arg + "': not a file, nor a bundled model (" + known + ")");
}

void warn_if_mesh_units_suspect(const std::string& file, double extent, const std::string& units) {
  if (extent > 0.5)
    std::cerr << fmt::format(
        "clumpkit: warning: {} is {:.4g} m across, read in {}: if the file is in millimetres, "
        "give --mesh-units mm\n",
        file, extent, units);
  else if (extent < 50e-6)
    std::cerr << fmt::format(
        "clumpkit: warning: {} is {:.4g} mm across, read in {}: check --mesh-units (the file's "
        "length unit)\n",
        file, extent * 1e3, units);
}

void MeshRepairFlags::add_to(CLI::App* command, const std::string& scope) {
  command->add_flag("--repair-orientation", orientation,
                    scope +
                        ": re-orient a closed, manifold mesh whose triangles disagree on "
                        "orientation (or whose bodies face inward) instead of refusing it");
  command->add_flag("--repair-holes", holes,
                    scope +
                        ": close the holes of an open, manifold mesh (a scan's gaps) with CGAL's "
                        "hole triangulation, then orient it, instead of refusing it");
}

void write_json(const nlohmann::json& j, const std::string& target) {
  const std::string text = j.dump(2) + "\n";
  if (target == "-") {
    std::cout << text;
  } else {
    write_file_atomic(target, text);
  }
}

}  // namespace clumpkit::cli

namespace clumpkit::cli {

std::vector<std::pair<int, Registration::Setup>>& registry() {
  static std::vector<std::pair<int, Registration::Setup>> r;
  return r;
}

Registration::Registration(int order, Setup setup) {
  registry().emplace_back(order, setup);
}

}  // namespace clumpkit::cli
