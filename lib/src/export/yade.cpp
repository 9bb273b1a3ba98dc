// Yade: a Python file for yade scripts. clumpTemplate() takes dimensionless radii and positions
// that BodyContainer.replaceByClumps() scales so the clump's volume, by Yade's grid estimate,
// equals the volume of the sphere it replaces; we give them in units of the union's
// volume-equivalent radius R_REF, and R_REPLACE, the sphere radius that Yade's estimate turns into
// the clump at true size. Absolute values, the union's mass properties and helpers that append the
// clump at true size with the union's mass properties follow.
#include <fmt/format.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "clumpkit/core/error.hpp"
#include "clumpkit/geometry/sphere.hpp"
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
double smallest_radius(const Spheres& s) {
  double r = INFINITY;
  for (const Sphere& sp : s) r = std::min(r, sp.radius);
  return r;
}
int yade_discretization(const Spheres& s) {
  const double cells = kYadeMaxCells * smallest_radius(s) / bounds(s).sizes().maxCoeff();
  return static_cast<int>(std::clamp(std::floor(cells), 1.0, 20.0));
}

// Yade's replaceByClumps sizes a clump by its own estimate of the template's volume: a grid over
// the template's box (cell edge the smallest relative radius / 5, or the box's longest side / 150
// if that is coarser), counting the cells whose centre lies inside a sphere, in Yade's loop order
// and arithmetic. A sphere of radius r becomes the template scaled by cbrt((4/3 pi r^3) / V).
// Returns the r that gives the scale r_ref, i.e. the clump at true size (docs/export.md).
double yade_replace_radius(const Spheres& rel, double r_ref) {
  const Eigen::AlignedBox3d box = bounds(rel);
  double dx = smallest_radius(rel) / 5.;
  const double longest = box.sizes().maxCoeff();
  if (longest / dx > 150) dx = longest / 150;
  const double dv = std::pow(dx, 3);
  double volume = 0.0;
  Eigen::Vector3d x;
  for (x.x() = box.min().x() + dx / 2.; x.x() < box.max().x(); x.x() += dx)
    for (x.y() = box.min().y() + dx / 2.; x.y() < box.max().y(); x.y() += dx)
      for (x.z() = box.min().z() + dx / 2.; x.z() < box.max().z(); x.z() += dx)
        for (const Sphere& sp : rel)
          if ((x - sp.center).squaredNorm() < std::pow(sp.radius, 2)) {
            volume += dv;
            break;
          }
  return r_ref * std::cbrt(3.0 * volume / (4.0 * std::numbers::pi));
}
}  // namespace

std::vector<ExportFile> render_yade(const ClumpTemplate& c, const ExportSettings& s) {
  require_principal_frame(c, "yade");
  if (c.spheres.size() < 2)
    throw InputError("", "spheres", "Yade's clumpTemplate needs at least 2 spheres");
  const MassProperties& m = c.mass;
  const double r_ref = std::cbrt(3.0 * m.volume / (4.0 * std::numbers::pi));
  std::vector<double> radii, rel_radii;
  Spheres rel;  // in units of R_REF: the template Yade sees
  for (const Sphere& sp : c.spheres) {
    radii.push_back(sp.radius);
    rel_radii.push_back(sp.radius / r_ref);
    rel.push_back({sp.center / r_ref, sp.radius / r_ref});
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
                   py_list(rel_radii), py_points(rel, 1.0));
  o += fmt::format(
      "# replaceByClumps([TEMPLATE], ...) sizes the clump by Yade's own grid estimate of the\n"
      "# template's volume, not the exact one: a sphere of radius R_REPLACE (not R_REF) becomes\n"
      "# the clump at true size. R_REPLACE replays that estimate (Yade 2023's algorithm).\n"
      "R_REPLACE = {}  # m\n",
      num(yade_replace_radius(rel, r_ref)));
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

    Replacing spheres by TEMPLATE instead: O.bodies.replaceByClumps([TEMPLATE], [amount],
    discretization=DISCRETIZATION), then set_union_mass on each new clump. Spheres of radius
    R_REPLACE become clumps at true size (R_REF gives them within about 1 %)."""
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
