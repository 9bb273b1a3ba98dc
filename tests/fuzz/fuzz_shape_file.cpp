// Fuzz target: shape files (shapes/pill_A.toml), through TomlDoc and load_shape's validation.
// An accepted cylinder is also filled by every paper preset (cheap, no integration): each fill
// either reports an InputError or gives valid spheres inside the cylinder.
#include <cmath>

#include "clumpkit/fill/paper_rule.hpp"
#include "clumpkit/geometry/shape_spec.hpp"
#include "fuzz_util.hpp"

namespace {

void check_fill(double d, double h, const clumpkit::PaperRule& rule) {
  using namespace clumpkit;
  const Spheres spheres = paper_fill(d, h, rule);
  CLUMPKIT_FUZZ_CHECK(static_cast<int>(spheres.size()) == sphere_count(rule), "sphere count");
  validate_spheres(spheres, "fill");  // throws InputError (a bug here: aborts below)
  const double tol = 1e-9 * std::max(d, h);
  for (const Sphere& s : spheres) {
    CLUMPKIT_FUZZ_CHECK(std::hypot(s.center.x(), s.center.y()) + s.radius <= 0.5 * d + tol,
                        "sphere leaves the lateral surface");
    CLUMPKIT_FUZZ_CHECK(std::abs(s.center.z()) + s.radius <= 0.5 * h + tol,
                        "sphere leaves an end face");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace clumpkit;
  const std::string text = fuzz::as_text(data, size);
  fuzz::input_errors_only([&] {
    const ShapeSpec s = parse_shape(text, "fuzz/shape.toml");
    CLUMPKIT_FUZZ_CHECK(std::isfinite(s.density) && s.density > 0.0, "density");
    CLUMPKIT_FUZZ_CHECK(s.mass_fraction > 0.0 && s.mass_fraction <= 1.0, "mass fraction");
    if (s.kind == ShapeSpec::Kind::Mesh) {
      CLUMPKIT_FUZZ_CHECK(std::isfinite(s.mesh_scale) && s.mesh_scale > 0.0, "mesh scale");
      return;
    }
    CLUMPKIT_FUZZ_CHECK(std::isfinite(s.diameter) && s.diameter > 0.0, "diameter");
    CLUMPKIT_FUZZ_CHECK(std::isfinite(s.height) && s.height > 0.0, "height");
    const CylinderRegime rg = regime(s.diameter, s.height);
    for (int n : paper_preset_counts(rg))
      fuzz::input_errors_only([&] { check_fill(s.diameter, s.height, paper_preset(rg, n)); });
  });
  return 0;
}
