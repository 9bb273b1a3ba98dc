// DEM-Engine (Project Chrono): the clump component CSV that LoadClumpType reads (header x,y,z,r,
// metres, positions relative to the centre of mass along the principal axes) and the mass and
// principal moments to pass to LoadClumpType(mass, MOI, file, material).
#include <fmt/format.h>

#include "format_text.hpp"
#include "table_csv.hpp"

namespace clumpkit::export_detail {

std::vector<ExportFile> render_deme(const ClumpTemplate& c, const ExportSettings& s) {
  require_principal_frame(c, "deme");  // DEME takes a diagonal MOI in the clump's own frame
  const std::string base = export_base_name(c, s);
  std::string spheres = "x,y,z,r\n";
  for (const Sphere& sp : c.spheres)
    spheres += fmt::format("{},{},{},{}\n", num(sp.center[0]), num(sp.center[1]), num(sp.center[2]),
                           num(sp.radius));
  return {{base + "_deme.csv", spheres}, {base + "_deme_mass.csv", mass_properties_csv(c)}};
}

}  // namespace clumpkit::export_detail
