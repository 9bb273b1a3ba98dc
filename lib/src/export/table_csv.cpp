#include "table_csv.hpp"

#include <fmt/format.h>

#include "format_text.hpp"

namespace clumpkit::export_detail {

std::string mass_properties_csv(const ClumpTemplate& c) {
  const MassProperties& m = c.mass;
  std::string o = "quantity,value,unit\n";
  auto row = [&](const std::string& q, double v, const char* unit) {
    o += fmt::format("{},{},{}\n", q, num(v), unit);
  };
  row("density", m.density, "kg/m^3");
  row("volume", m.volume, "m^3");
  row("mass", m.mass, "kg");
  const char* axis = "xyz";
  for (int k = 0; k < 3; ++k) row(fmt::format("com_{}", axis[k]), m.center_of_mass[k], "m");
  for (int k = 0; k < 3; ++k)
    row(fmt::format("principal_moment_{}", axis[k]), m.principal_moments[k], "kg m^2");
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
      row(fmt::format("I{}{}", axis[i], axis[j]), m.inertia_tensor(i, j), "kg m^2");
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      row(fmt::format("rotation_{}{}", i + 1, j + 1), c.rotation(i, j), "1");
  for (int k = 0; k < 3; ++k) row(fmt::format("translation_{}", axis[k]), c.translation[k], "m");
  return o;
}

}  // namespace clumpkit::export_detail
