#include "clumpkit/calibrate/model_writer.hpp"

#include <fmt/format.h>

namespace clumpkit::calibrate {

namespace fs = std::filesystem;

namespace {
std::string rel(const fs::path& p, const fs::path& target) {
  if (p.empty()) return "";
  std::error_code ec;
  const fs::path base = fs::absolute(target, ec).parent_path();
  const fs::path r = fs::relative(fs::absolute(p, ec), base, ec);
  return (ec || r.empty() ? fs::absolute(p) : r).generic_string();
}
std::string partners(const std::string& name, const std::map<std::string, double>& v) {
  std::string s = "\n[effects." + name + "]\n";
  for (const auto& [k, x] : v) s += fmt::format("{} = {:.10g}\n", k, x);
  return s;
}
}  // namespace

std::string format_model(const ParticleModel& m, const fs::path& target, const std::string& note) {
  std::string s = "# Written by clumpkit";
  if (!note.empty()) s += ": " + note;
  s += "\n\n[model]\n";
  s += fmt::format("name = \"{}\"\n", m.name);
  if (!m.description.empty()) s += fmt::format("description = \"{}\"\n", m.description);
  if (!m.materials_path.empty())
    s += fmt::format("materials = \"{}\"\n", rel(m.materials_path, target));
  s += fmt::format("mass_basis = \"{}\"\n", to_string(m.mass_basis));
  for (const auto& t : m.types) {
    s += "\n[[types]]\n";
    s += fmt::format("name = \"{}\"\n", t.name);
    if (!t.shape_path.empty()) s += fmt::format("shape = \"{}\"\n", rel(t.shape_path, target));
    if (t.paper_spheres) s += fmt::format("paper_spheres = {}\n", *t.paper_spheres);
    if (!t.paper_spheres && !t.clump_path.empty())
      s += fmt::format("clump = \"{}\"\n", rel(t.clump_path, target));
    if (m.types.size() > 1) s += fmt::format("mass_fraction = {:.10g}\n", t.mass_fraction);
    if (t.given_mass) s += fmt::format("mass = \"{:.10g} kg\"\n", *t.given_mass);
  }
  const ModelEffects& e = m.effects;
  s +=
      "\n# Contact-law effects that are ON; an effect not listed is absent (SPEC §8).\n[effects]\n";
  if (e.particle_friction)
    s += fmt::format("particle_friction = {{ value = {:.10g} }}\n", *e.particle_friction);
  if (e.size_distribution && e.height_spread > 0)
    s += fmt::format("size_distribution = {{ height_spread = {:.10g} }}\n", e.height_spread);
  else if (e.size_distribution)
    s += "size_distribution = true\n";
  if (e.rolling_friction) s += partners("rolling_friction", *e.rolling_friction);
  if (e.wall_friction) s += partners("wall_friction", *e.wall_friction);
  if (e.restitution) s += partners("restitution", *e.restitution);
  if (e.cohesion)
    s += fmt::format("\n[effects.cohesion]\nenergy_density = \"{:.10g} J/m^3\"\n", *e.cohesion);
  if (e.shape_resolution)
    s += fmt::format("\n[effects.shape_resolution]\nspheres = {}\n", *e.shape_resolution);
  if (e.rolling_model)
    s += fmt::format("\n[effects.rolling_model]\nmodel = \"{}\"\nviscous_damping = {:.10g}\n",
                     dem::to_string(*e.rolling_model), e.epsd_damping);
  return s;
}

}  // namespace clumpkit::calibrate
