// Yade: a Python file for yade scripts. clumpTemplate() takes dimensionless radii and positions
// that BodyContainer.replaceByClumps() scales so the clump's volume equals the volume of the
// sphere it replaces; we give them in units of the union's volume-equivalent radius R_REF, so a
// replaced sphere of radius R_REF yields the clump at its true size. Absolute values, the union's
// mass properties and a helper that appends the clump at true size follow.
#include <fmt/format.h>

#include <algorithm>
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
// Yade's grid cell is the smallest radius / discretization, and its grid spans the clump's box:
// 20 cells per smallest radius (the centre of mass within 0.01 of that radius on the paper's
// pills, docs/export.md), but no more than kYadeMaxCells along the box's longest side, so a
// clump with a tiny sphere does not cost Yade seconds per clump.
constexpr int kYadeMaxCells = 100;
int yade_discretization(const Spheres& s) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  double r_min = INFINITY;
  for (const Sphere& sp : s) {
    lo = lo.cwiseMin(sp.center - Eigen::Vector3d::Constant(sp.radius));
    hi = hi.cwiseMax(sp.center + Eigen::Vector3d::Constant(sp.radius));
    r_min = std::min(r_min, sp.radius);
  }
  const double cells = kYadeMaxCells * r_min / (hi - lo).maxCoeff();
  return static_cast<int>(std::clamp(std::floor(cells), 1.0, 20.0));
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
  // Yade 2020 and later (Debian's 2023.02a) ship minieigen as yade.minieigenHP; a plain
  // `from minieigen import` fails there (found by running the file in Debian's Yade,
  // tests/peer/yade_clump.py).
  o += "from yade import utils\n"
       "try:\n"
       "    from yade.minieigenHP import Vector3  # Yade 2020 and later\n"
       "except ImportError:\n"
       "    from minieigen import Vector3  # older Yade\n\n";
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
  o += fmt::format(
      "# Cells per smallest sphere radius of Yade's grid integration of the union\n"
      "# (appendClumped, replaceByClumps): 20, or fewer so that the clump's longest side has\n"
      "# at most {} cells. With 0 Yade sums the member spheres, overlaps and all: their mass,\n"
      "# centre of mass and inertia, not the union's.\nDISCRETIZATION = {}\n",
      kYadeMaxCells, yade_discretization(c.spheres));
  o += R"(

def set_union_mass(clump_id):
    """Sets the clump's mass and principal moments to the sphere union's (MASS,
    PRINCIPAL_MOMENTS). Yade orders a clump's principal axes itself, so the moments go to its
    axes in the rank order of its own moments. Yade's reference point (the centre of mass) stays
    its own: create the clump with discretization=DISCRETIZATION so that point is the union's
    centre of mass, not the spheres' mean weighted by their whole volumes."""
    state = O.bodies[clump_id].state
    own = [state.inertia[k] for k in range(3)]
    order = sorted(range(3), key=lambda k: own[k])
    ours = sorted(PRINCIPAL_MOMENTS)
    moments = [0.0, 0.0, 0.0]
    for rank, k in enumerate(order):
        moments[k] = ours[rank]
    state.mass = MASS
    state.inertia = Vector3(*moments)


def add_clump(center, material=-1, union_mass=True, orientation=None):
    """Appends the clump at true size with its centre of mass at `center` (m) and returns the
    clump's body id. `orientation` (a Yade Quaternion; None = the template's frame) turns the
    clump about its centre of mass, e.g. Quaternion(axis, angle) with a random axis and angle
    for a random packing. With union_mass (the default), Yade integrates the union on its grid
    (DISCRETIZATION), which puts the clump's reference point at the union's centre of mass, and
    the mass and principal moments are then set to the union's exact values (set_union_mass).
    Without it, Yade's own sum over the spheres stands (overlaps counted more than once).

    Replacing spheres by TEMPLATE instead (O.bodies.replaceByClumps([TEMPLATE], [amount],
    discretization=DISCRETIZATION), then set_union_mass on each new clump): Yade sizes the clump
    by its own coarse grid estimate of the template's volume, so a replaced sphere of radius
    R_REF gives the clump within about 1 % of its true size, not exactly at it."""
    c = Vector3(*center)
    turn = (lambda v: orientation * v) if orientation is not None else (lambda v: v)
    clump_id, _ = O.bodies.appendClumped(
        [utils.sphere(c + turn(Vector3(*p)), r, material=material)
         for p, r in zip(POSITIONS, RADII)],
        discretization=DISCRETIZATION if union_mass else 0)
    if union_mass:
        set_union_mass(clump_id)
    return clump_id
)";
  return {{export_base_name(c, s) + "_yade.py", o}};
}

}  // namespace clumpkit::export_detail
