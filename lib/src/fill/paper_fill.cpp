#include "clumpkit/fill/paper_fill.hpp"

#include "clumpkit/core/error.hpp"

namespace clumpkit {

ClumpTemplate paper_fill_template(const ShapeSpec& shape, const PaperFillRequest& req) {
  const std::string where = shape.path.empty() ? shape.name : shape.path.string();
  if (shape.kind != ShapeSpec::Kind::Cylinder)
    throw InputError(where, "shape.kind",
                     "the paper's rules fill cylinders only (use --method "
                     "optimal or edt for meshes)");
  const CylinderRegime rg = regime(shape.diameter, shape.height);
  PaperRule rule;
  Spheres spheres;
  try {
    rule = req.custom ? *req.custom : paper_preset(rg, req.spheres);
    spheres = paper_fill(shape.diameter, shape.height, rule);
  } catch (const InputError& e) {
    throw e.at(where);
  }
  ClumpTemplate c = make_clump_template(spheres, shape.density, req.sampling);
  c.name = shape.name + "_" + std::to_string(spheres.size());
  c.source = {{"shape", shape.name},        {"file", shape.path.string()},
              {"kind", "cylinder"},         {"diameter", shape.diameter},
              {"height", shape.height},     {"density", shape.density},
              {"material", shape.material}, {"mass_fraction", shape.mass_fraction}};
  c.method = {{"name", "paper"},
              {"regime", to_string(rg)},
              {"spheres", spheres.size()},
              {"layers", rule.layers},
              {"per_ring", rule.per_ring},
              {"axial", to_string(rule.axial)},
              {"radius_rule", to_string(rule.radius_rule)},
              {"sphere_radius", spheres.front().radius}};
  return c;
}

const std::vector<PaperModel>& paper_models() {
  static const std::vector<PaperModel> m = {{'A', 4},  {'A', 12}, {'A', 20}, {'B', 4}, {'B', 12},
                                            {'B', 20}, {'C', 2},  {'C', 12}, {'C', 18}};
  return m;
}

}  // namespace clumpkit
