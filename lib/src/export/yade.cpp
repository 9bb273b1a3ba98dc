// Yade: a Python file for yade scripts. clumpTemplate() takes dimensionless radii and positions
// that BodyContainer.replaceByClumps() scales so the clump's volume equals the volume of the
// sphere it replaces; we give them in units of the union's volume-equivalent radius R_REF, so a
// replaced sphere of radius R_REF yields the clump at its true size. Absolute values, the union's
// mass properties and a helper that appends the clump at true size follow.
#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "clumpkit/core/error.hpp"
#include "format_text.hpp"

namespace clumpkit::export_detail {

namespace {
std::string py_list(const std::vector<double>& v) {
  std::string o = "[";
  for (size_t i = 0; i < v.size(); ++i) o += fmt::format("{}{}", i ? ", " : "", num(v[i]));
  return o + "]";
}
std::string py_points(const Spheres& s, double scale) {
  std::string o = "[";
  for (size_t i = 0; i < s.size(); ++i)
    o += fmt::format("{}\n    [{}, {}, {}]", i ? "," : "", num(s[i].center[0] / scale),
                     num(s[i].center[1] / scale), num(s[i].center[2] / scale));
  return o + "]";
}
}  // namespace

std::vector<ExportFile> render_yade(const ClumpTemplate& c, const ExportSettings& s) {
  require_principal_frame(c, "yade");
  if (c.spheres.size() < 2)
    throw InputError("", "spheres", "Yade's clumpTemplate needs at least 2 spheres");
  const MassProperties& m = c.mass;
  const double r_ref = std::cbrt(3.0 * m.volume / (4.0 * std::numbers::pi));
  std::vector<double> radii, rel_radii;
  for (const Sphere& sp : c.spheres) {
    radii.push_back(sp.radius);
    rel_radii.push_back(sp.radius / r_ref);
  }
  std::string o = provenance_block(c, "yade", "# ");
  o += "# Run inside Yade (yade script.py). Lengths in m, masses in kg.\n";
  o += "from yade import utils\nfrom minieigen import Vector3\n\n";
  o += fmt::format(
      "# Volume-equivalent radius of the sphere union: the unit of relRadii and\n"
      "# relPositions below.\nR_REF = {}  # m\n",
      num(r_ref));
  o += fmt::format("DENSITY = {}  # kg/m^3\nVOLUME = {}  # m^3 (sphere union)\nMASS = {}  # kg\n",
                   num(m.density), num(m.volume), num(m.mass));
  o += fmt::format(
      "PRINCIPAL_MOMENTS = {}  # kg m^2, along template x, y, z\n",
      py_list({m.principal_moments[0], m.principal_moments[1], m.principal_moments[2]}));
  o += "# p_source = ROTATION * p_template + TRANSLATION\n";
  o += "ROTATION = [";
  for (int i = 0; i < 3; ++i)
    o += fmt::format("{}{}", i ? ", " : "",
                     py_list({c.rotation(i, 0), c.rotation(i, 1), c.rotation(i, 2)}));
  o += "]\n";
  o += fmt::format("TRANSLATION = {}  # m\n\n",
                   py_list({c.translation[0], c.translation[1], c.translation[2]}));
  o += fmt::format("RADII = {}  # m\n", py_list(radii));
  o += fmt::format("POSITIONS = {}  # m, relative to the centre of mass\n\n",
                   py_points(c.spheres, 1.0));
  o += fmt::format("TEMPLATE = utils.clumpTemplate(\n    relRadii={},\n    relPositions={})\n\n",
                   py_list(rel_radii), py_points(c.spheres, r_ref));
  o += R"(
def add_clump(center, material=-1, union_mass=True):
    """Appends the clump at true size with its centre of mass at `center` (m) and returns the
    clump's body id. With union_mass, the body's mass and principal moments are set to the sphere
    union's (Yade's own estimate treats overlaps approximately); the moments are assigned in the
    rank order of Yade's own principal moments, since Yade orders its clump axes itself."""
    c = Vector3(*center)
    clump_id, _ = O.bodies.appendClumped(
        [utils.sphere(c + Vector3(*p), r, material=material) for p, r in zip(POSITIONS, RADII)])
    if union_mass:
        state = O.bodies[clump_id].state
        own = [state.inertia[k] for k in range(3)]
        order = sorted(range(3), key=lambda k: own[k])
        ours = sorted(PRINCIPAL_MOMENTS)
        moments = [0.0, 0.0, 0.0]
        for rank, k in enumerate(order):
            moments[k] = ours[rank]
        state.mass = MASS
        state.inertia = Vector3(*moments)
    return clump_id
)";
  return {{export_base_name(c, s) + "_yade.py", o}};
}

}  // namespace clumpkit::export_detail
