// MercuryDPM clumps (the MClump layout its ClumpIO reads): one folder per clump with Clump.txt
// (x,y,z,r per pebble), Mass.txt (kg), TOI.txt (tensor of inertia about the centre of mass,
// 3 rows, kg m^2) and PD.txt (principal directions as rows). Those four files hold numbers only,
// so the frame and provenance go to a side file.
#include <fmt/format.h>

#include "format_text.hpp"

namespace clumpkit::export_detail {

std::vector<ExportFile> render_mercurydpm(const ClumpTemplate& c, const ExportSettings& s) {
  require_principal_frame(c, "mercurydpm");
  const std::string dir = export_base_name(c, s) + "/";
  std::string clump;
  for (const Sphere& sp : c.spheres)
    clump += fmt::format("{},{},{},{}\n", num(sp.center[0]), num(sp.center[1]), num(sp.center[2]),
                         num(sp.radius));
  const Eigen::Matrix3d I = principal_inertia(c);
  std::string toi, pd;
  for (int i = 0; i < 3; ++i) {
    toi += fmt::format("{},{},{}\n", num(I(i, 0)), num(I(i, 1)), num(I(i, 2)));
    // The template frame is principal: its axes are the principal directions.
    const Eigen::Vector3d axis = Eigen::Vector3d::Unit(i);
    pd += fmt::format("{},{},{}\n", num(axis[0]), num(axis[1]), num(axis[2]));
  }
  std::string side = provenance_block(c, "mercurydpm", "# ");
  side +=
      "# PD.txt rows are the principal axes in the template frame (the identity); TOI.txt is\n"
      "# the union's inertia tensor about its centre of mass in that frame, i.e.\n"
      "# diag(principal moments).\n";
  return {{dir + "Clump.txt", clump},
          {dir + "Mass.txt", num(c.mass.mass) + "\n"},
          {dir + "TOI.txt", toi},
          {dir + "PD.txt", pd},
          {dir + "clumpkit_frame.txt", side}};
}

}  // namespace clumpkit::export_detail
