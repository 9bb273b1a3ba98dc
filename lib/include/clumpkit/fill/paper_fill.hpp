#pragma once
/// The paper's rules applied to a cylinder shape, producing a complete clump template.
#include <optional>

#include "clumpkit/fill/paper_rule.hpp"
#include "clumpkit/geometry/clump_template.hpp"
#include "clumpkit/geometry/shape_spec.hpp"

namespace clumpkit {

struct PaperFillRequest {
  int spheres = 12;                 ///< a preset count, used when `custom` is empty
  std::optional<PaperRule> custom;  ///< an explicit rule of the family
  RaySamplingOptions sampling;      ///< for the union's mass properties
};

/// Throws InputError naming the shape file and field for a non-cylinder shape or a rule that does
/// not fit.
ClumpTemplate paper_fill_template(const ShapeSpec& shape, const PaperFillRequest& request);

/// The paper's nine models: (shape name, sphere count) = A/B 4, 12, 20 and C 2, 12, 18.
struct PaperModel {
  char pill;
  int spheres;
};
const std::vector<PaperModel>& paper_models();

}  // namespace clumpkit
