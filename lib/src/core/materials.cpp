#include "clumpkit/core/materials.hpp"

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/core/toml_doc.hpp"

namespace clumpkit {

std::pair<std::string, std::string> MaterialLibrary::key(const std::string& a,
                                                         const std::string& b) {
  return a < b ? std::make_pair(a, b) : std::make_pair(b, a);
}

void MaterialLibrary::add(const Material& m) {
  materials_[m.name] = m;
}

void MaterialLibrary::set_interaction(const std::string& a, const std::string& b,
                                      const Interaction& i) {
  interactions_[key(a, b)] = i;
}

const Material& MaterialLibrary::get(const std::string& name, const std::string& where,
                                     const std::string& field) const {
  auto it = materials_.find(name);
  if (it == materials_.end()) {
    std::string known;
    for (const auto& [n, m] : materials_) known += (known.empty() ? "" : ", ") + n;
    throw InputError(where, field, "unknown material '" + name + "' (known: " + known + ")");
  }
  return it->second;
}

bool MaterialLibrary::has_interaction(const std::string& a, const std::string& b) const {
  return interactions_.count(key(a, b)) != 0;
}

const Interaction& MaterialLibrary::interaction(const std::string& a, const std::string& b,
                                                const std::string& where) const {
  auto it = interactions_.find(key(a, b));
  if (it == interactions_.end())
    throw InputError(where, "interactions",
                     "no contact properties for the material pair '" + a + "' / '" + b + "'");
  return it->second;
}

std::vector<std::string> MaterialLibrary::names() const {
  std::vector<std::string> out;
  for (const auto& [n, m] : materials_) out.push_back(n);
  return out;
}

MaterialLibrary MaterialLibrary::load(const std::filesystem::path& path) {
  return parse(read_file(path), path.string());
}

MaterialLibrary MaterialLibrary::parse(const std::string& text, const std::string& where) {
  TomlDoc doc = TomlDoc::parse(text, where);
  MaterialLibrary lib;
  for (const std::string& name : doc.keys("materials")) {
    const std::string p = "materials." + name + ".";
    Material m;
    m.name = name;
    m.density = doc.quantity(p + "density", Dimension::Density);
    doc.require_range(p + "density", m.density, 0.0, 1e6, true);
    m.poisson_ratio = doc.number(p + "poisson_ratio");
    doc.require_range(p + "poisson_ratio", m.poisson_ratio, -1.0, 0.5, true, true);
    m.youngs_modulus = doc.quantity(p + "youngs_modulus", Dimension::Pressure);
    doc.require_range(p + "youngs_modulus", m.youngs_modulus, 0.0, 1e13, true);
    lib.add(m);
  }
  if (lib.materials_.empty()) throw InputError(where, "materials", "no materials defined");
  const size_t n = doc.array_size("interactions");
  for (size_t k = 0; k < n; ++k) {
    const std::string p = "interactions." + std::to_string(k) + ".";
    auto pair = doc.strings(p + "pair");
    if (pair.size() != 2) doc.fail(p + "pair", "expected two material names");
    for (const auto& name : pair) lib.get(name, where, p + "pair");
    Interaction i;
    i.restitution = doc.number(p + "restitution");
    doc.require_range(p + "restitution", i.restitution, 0.0, 1.0, true, false);
    i.static_friction = doc.number(p + "static_friction");
    doc.require_range(p + "static_friction", i.static_friction, 0.0, 10.0);
    i.rolling_friction = doc.number_opt(p + "rolling_friction").value_or(0.0);
    doc.require_range(p + "rolling_friction", i.rolling_friction, 0.0, 10.0);
    lib.set_interaction(pair[0], pair[1], i);
  }
  return lib;
}

MaterialLibrary MaterialLibrary::paper_table1() {
  MaterialLibrary lib;
  lib.add({"pill", 1380.0, 0.350, 1.100e8});
  lib.add({"abs_plastic", 1050.0, 0.394, 3.189e9});
  lib.add({"organic_glass", 1800.0, 0.350, 1.300e9});
  lib.add({"galvanized_steel", 7865.0, 0.300, 7.900e10});
  lib.set_interaction("pill", "pill", {0.201, 0.466, 0.080});
  lib.set_interaction("pill", "abs_plastic", {0.299, 0.577, 0.120});
  lib.set_interaction("pill", "organic_glass", {0.279, 0.533, 0.050});
  lib.set_interaction("pill", "galvanized_steel", {0.305, 0.511, 0.070});
  return lib;
}

}  // namespace clumpkit
