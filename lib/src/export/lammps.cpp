// LAMMPS molecule file for `molecule` + `fix rigid/small ... mol`. The header's mass, com and
// inertia lines make LAMMPS use the union's properties instead of summing point masses; the
// per-atom Masses only matter for per-atom output and are the union mass split by sphere volume.
#include <fmt/format.h>

#include "format_text.hpp"

namespace clumpkit::export_detail {

std::vector<ExportFile> render_lammps(const ClumpTemplate& c, const ExportSettings& s) {
  require_principal_frame(c, "lammps");
  const std::string base = export_base_name(c, s);
  const MassProperties& m = c.mass;
  const Eigen::Matrix3d I = principal_inertia(c);
  const size_t n = c.spheres.size();
  // LAMMPS skips the first line; keep it short (it reads 256-byte lines).
  std::string o = fmt::format("clumpkit clump {} ({} spheres, SI units)\n", base, n);
  o += provenance_block(c, "lammps", "# ");
  o += "# Per-atom Masses below are the union mass distributed in proportion to sphere volume\n"
       "# (r^3); they sum to the union mass. The body mass, com and inertia come from the\n"
       "# header lines, i.e. from the sphere union, not from the per-atom masses.\n"
       "# inertia line: Ixx Iyy Izz Ixy Ixz Iyz (about the com, kg m^2). The template frame is\n"
       "# principal, so the tensor is diag(principal moments) and the off-diagonal terms are 0\n"
       "# (which also sidesteps LAMMPS's reader taking the last three as Iyz Ixz Ixy).\n\n";
  o += fmt::format("{} atoms\n", n);
  o += fmt::format("{} mass\n", num(m.mass));
  o += fmt::format("{} {} {} com\n", num(m.center_of_mass[0]), num(m.center_of_mass[1]),
                   num(m.center_of_mass[2]));
  o += fmt::format("{} {} {} {} {} {} inertia\n", num(I(0, 0)), num(I(1, 1)), num(I(2, 2)),
                   num(I(0, 1)), num(I(0, 2)), num(I(1, 2)));
  o += "\nCoords\n\n";
  for (size_t i = 0; i < n; ++i) {
    const Sphere& sp = c.spheres[i];
    o += fmt::format("{} {} {} {}\n", i + 1, num(sp.center[0]), num(sp.center[1]),
                     num(sp.center[2]));
  }
  o += "\nTypes\n\n";
  for (size_t i = 0; i < n; ++i) o += fmt::format("{} {}\n", i + 1, s.atom_type);
  o += "\nDiameters\n\n";
  for (size_t i = 0; i < n; ++i) o += fmt::format("{} {}\n", i + 1, num(2.0 * c.spheres[i].radius));
  o += "\nMasses\n\n";
  const std::vector<double> masses = volume_weighted_masses(c);
  for (size_t i = 0; i < n; ++i) o += fmt::format("{} {}\n", i + 1, num(masses[i]));
  return {{base + ".mol", o}};
}

}  // namespace clumpkit::export_detail
