#pragma once
/// The paper's tangency rules (paper §2.2, SPEC §3) as one parametric family for any cylinder of
/// diameter D and height H, axis z, centred at its centre of mass:
///   - k layers of spheres of one radius r, layer centres evenly spaced on z in
///     [-(H/2 - r), +(H/2 - r)], so the outer layers touch the end faces;
///   - r = H / (k + 1) ("height" rule: the layers overlap and span the height) or r = D / 2
///     ("diameter" rule: spheres as wide as the pill);
///   - on every layer a ring of n spheres at radius D/2 - r (tangent to the lateral surface), the
///     first on +x; optionally one sphere on the axis on the outer layers or on every layer.
/// The regime is "flat" when H <= D and "tall" otherwise; each regime has the paper's presets.
#include <string>
#include <vector>

#include "clumpkit/geometry/sphere.hpp"

namespace clumpkit {

struct PaperRule {
  int layers = 2;
  int per_ring = 6;  ///< 0: no ring
  enum class Axial { None, Outer, All } axial = Axial::None;
  enum class Radius { Height, Diameter } radius_rule = Radius::Height;
};

enum class CylinderRegime { Flat, Tall };
CylinderRegime regime(double diameter, double height);
const char* to_string(CylinderRegime r);
const char* to_string(PaperRule::Axial a);
const char* to_string(PaperRule::Radius r);

/// The paper's preset for a sphere count in a regime: flat 4, 12, 20; tall 2, 12, 18.
/// Throws InputError(field "spheres") listing the available counts otherwise.
PaperRule paper_preset(CylinderRegime regime, int spheres);
std::vector<int> paper_preset_counts(CylinderRegime regime);

/// Spheres in the cylinder's frame (metres). Throws InputError naming the offending parameter when
/// a sphere would leave the cylinder or the rule is degenerate (e.g. a ring collapsing on the
/// axis, coincident spheres).
Spheres paper_fill(double diameter, double height, const PaperRule& rule);

/// Number of spheres the rule produces.
int sphere_count(const PaperRule& rule);

}  // namespace clumpkit
