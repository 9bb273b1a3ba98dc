#include "clumpkit/fill/paper_rule.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "clumpkit/core/error.hpp"

namespace clumpkit {

CylinderRegime regime(double d, double h) {
  return h <= d ? CylinderRegime::Flat : CylinderRegime::Tall;
}
const char* to_string(CylinderRegime r) {
  return r == CylinderRegime::Flat ? "flat" : "tall";
}
const char* to_string(PaperRule::Axial a) {
  switch (a) {
    case PaperRule::Axial::None:
      return "none";
    case PaperRule::Axial::Outer:
      return "outer";
    case PaperRule::Axial::All:
      return "all";
  }
  return "?";
}
const char* to_string(PaperRule::Radius r) {
  return r == PaperRule::Radius::Height ? "height" : "diameter";
}

std::vector<int> paper_preset_counts(CylinderRegime regime) {
  return regime == CylinderRegime::Flat ? std::vector<int>{4, 12, 20} : std::vector<int>{2, 12, 18};
}

PaperRule paper_preset(CylinderRegime rg, int n) {
  using A = PaperRule::Axial;
  using R = PaperRule::Radius;
  if (rg == CylinderRegime::Flat) {
    if (n == 4) return {1, 4, A::None, R::Height};
    if (n == 12) return {2, 6, A::None, R::Height};
    if (n == 20) return {3, 6, A::Outer, R::Height};
  } else {
    if (n == 2) return {2, 0, A::All, R::Diameter};
    if (n == 12) return {2, 6, A::None, R::Height};
    if (n == 18) return {3, 6, A::None, R::Height};
  }
  std::ostringstream ss;
  ss << "the paper's rules have no " << n << "-sphere model for a " << to_string(rg)
     << " cylinder (H " << (rg == CylinderRegime::Flat ? "<=" : ">") << " D); available:";
  for (int c : paper_preset_counts(rg)) ss << " " << c;
  ss << " (or give --layers/--per-ring/--axial for a custom rule)";
  throw InputError("", "spheres", ss.str());
}

int sphere_count(const PaperRule& r) {
  int axial = r.axial == PaperRule::Axial::All     ? r.layers
              : r.axial == PaperRule::Axial::Outer ? std::min(r.layers, 2)
                                                   : 0;
  return r.layers * r.per_ring + axial;
}

Spheres paper_fill(double d, double h, const PaperRule& rule) {
  if (!(d > 0.0) || !std::isfinite(d)) throw InputError("", "diameter", "must be positive");
  if (!(h > 0.0) || !std::isfinite(h)) throw InputError("", "height", "must be positive");
  if (rule.layers < 1 || rule.layers > 50)
    throw InputError("", "layers", "must be between 1 and 50, got " + std::to_string(rule.layers));
  if (rule.per_ring < 0 || rule.per_ring == 1 || rule.per_ring > 64)
    throw InputError("", "per_ring",
                     "must be 0 (no ring) or 2..64, got " + std::to_string(rule.per_ring));
  if (rule.per_ring == 0 && rule.axial == PaperRule::Axial::None)
    throw InputError("", "axial", "a rule without a ring needs axial spheres");
  const int k = rule.layers;
  const double r = rule.radius_rule == PaperRule::Radius::Height ? h / (k + 1) : 0.5 * d;
  const double tol = 1e-12 * std::max(d, h);
  std::ostringstream why;
  if (r > 0.5 * h + tol) {
    why << "sphere radius " << r * 1e3 << " mm exceeds half the height " << 0.5 * h * 1e3
        << " mm: spheres would leave through the end faces";
    throw InputError("", "radius_rule", why.str());
  }
  if (r > 0.5 * d + tol) {
    why << "sphere radius " << r * 1e3 << " mm exceeds half the diameter " << 0.5 * d * 1e3
        << " mm: spheres would leave through the lateral surface";
    throw InputError("", "layers", why.str());
  }
  const double ring = 0.5 * d - r;
  if (rule.per_ring > 0 && ring <= tol) {
    why << "ring radius D/2 - r = " << ring * 1e3
        << " mm: the ring collapses onto the axis (use axial spheres instead)";
    throw InputError("", "per_ring", why.str());
  }
  const double zmax = 0.5 * h - r;
  if (k > 1 && zmax <= tol) throw InputError("", "layers", "layers coincide (H/2 - r = 0)");

  Spheres out;
  for (int layer = 0; layer < k; ++layer) {
    // Top layer first, as the paper numbers its spheres.
    const double z = k == 1 ? 0.0 : zmax - 2.0 * zmax * layer / (k - 1);
    for (int i = 0; i < rule.per_ring; ++i) {
      const double a = 2.0 * std::numbers::pi * i / rule.per_ring;
      out.push_back({Eigen::Vector3d(ring * std::cos(a), ring * std::sin(a), z), r});
    }
    const bool outer = layer == 0 || layer == k - 1;
    if (rule.axial == PaperRule::Axial::All || (rule.axial == PaperRule::Axial::Outer && outer))
      out.push_back({Eigen::Vector3d(0.0, 0.0, z), r});
  }
  // Snap round-off (cos 90° etc.) so that symmetric fills are exactly symmetric.
  for (Sphere& s : out)
    for (int c = 0; c < 3; ++c)
      if (std::abs(s.center[c]) < 1e-15) s.center[c] = 0.0;
  return out;
}

}  // namespace clumpkit
