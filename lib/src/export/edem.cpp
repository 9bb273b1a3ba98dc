// EDEM: the sphere table EDEM's particle editor imports (x,y,z,radius in the principal frame,
// metres) and the union's mass properties in a second CSV, since EDEM computes its own from the
// spheres unless they are entered by hand.
#include <fmt/format.h>

#include "format_text.hpp"
#include "table_csv.hpp"

namespace clumpkit::export_detail {

std::vector<ExportFile> render_edem(const ClumpTemplate& c, const ExportSettings& s) {
  require_principal_frame(c, "edem");
  const std::string base = export_base_name(c, s);
  std::string spheres = "x,y,z,radius\n";
  for (const Sphere& sp : c.spheres)
    spheres += fmt::format("{},{},{},{}\n", num(sp.center[0]), num(sp.center[1]), num(sp.center[2]),
                           num(sp.radius));
  return {{base + "_spheres.csv", spheres}, {base + "_mass.csv", mass_properties_csv(c)}};
}

}  // namespace clumpkit::export_detail
