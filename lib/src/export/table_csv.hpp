#pragma once
// A "quantity,value,unit" CSV of the union's mass properties and the frame transform, shared by
// the EDEM and DEM-Engine exports.
#include <string>

#include "clumpkit/geometry/clump_template.hpp"

namespace clumpkit::export_detail {

std::string mass_properties_csv(const ClumpTemplate& c);

}  // namespace clumpkit::export_detail
