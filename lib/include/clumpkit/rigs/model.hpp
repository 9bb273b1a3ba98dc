#pragma once
/// A particle model: which clump each pill type uses, the type mass fractions, the materials, the
/// mass basis and the contact-law effects that are on (SPEC §2, §8). Read from a human-edited
/// TOML file such as shapes/models/production.toml; every error names file:line and key.
///
/// An effect that is not listed under [effects] is absent from the physics (no spring, no
/// damping, no torque), not merely zero. Effect ids are those of SPEC §8.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "clumpkit/core/materials.hpp"
#include "clumpkit/dem/contact_law.hpp"
#include "clumpkit/dem/world.hpp"
#include "clumpkit/geometry/clump_template.hpp"
#include "clumpkit/geometry/shape_spec.hpp"

namespace clumpkit {

/// The effect ids of SPEC §8, in catalogue order.
const std::vector<std::string>& effect_names();
/// Throws InputError(where, field, "unknown effect ... (known: ...)").
void check_effect_name(const std::string& name, const std::string& where, const std::string& field);

/// How the clump's mass is obtained (SPEC §2): the union of its spheres at the pill density,
/// the true cylinder's mass, or a mass given in the model file. The inertia tensor is the union's,
/// scaled by the same factor as the mass.
enum class MassBasis { kSphereUnion, kTrueShape, kGiven };
const char* to_string(MassBasis b);

/// One pill type of the population.
struct ModelType {
  std::string name;                  ///< e.g. "A"; used as the DEM clump-type name
  std::filesystem::path shape_path;  ///< the shape file (shapes/pill_A.toml)
  ShapeSpec shape;
  std::optional<int> paper_spheres;  ///< paper rule preset (A/B 4, 12, 20; C 2, 12, 18)
  std::filesystem::path clump_path;  ///< or a clump template file (clumpkit-clump/1)
  double mass_fraction = 1.0;        ///< normalised over the model's types
  std::optional<double> given_mass;  ///< kg per pill, basis `given`
  /// A height class of a size distribution (ParticleModel::population()): the shape's height is
  /// the type's times this factor, filled by the type's paper rule of its own regime.
  double height_factor = 1.0;
};

/// The largest height spread a model may state: the short class keeps 48 % of the height.
inline constexpr double kMaxHeightSpread = 0.3;

/// Values of the effects that are on. Per-partner values (key = the other material, "pill" for
/// pill–pill) default to the materials library's interaction with the pill.
struct ModelEffects {
  std::optional<std::map<std::string, double>> rolling_friction;  ///< μr, 1
  std::optional<double> particle_friction;                        ///< μs pill–pill
  std::optional<std::map<std::string, double>> wall_friction;     ///< μs pill–wall
  std::optional<std::map<std::string, double>> restitution;       ///< e
  std::optional<double> cohesion;       ///< simplified JKR energy density, J/m^3 (pill–pill)
  std::optional<int> shape_resolution;  ///< sphere count forced on every paper-rule type
  bool size_distribution = false;       ///< on: the types' mass fractions are used
  /// size_distribution: relative standard deviation of every type's pill height, 1 (0: one
  /// height per type). The DEM sees each type as three height classes (population()).
  double height_spread = 0.0;
  std::optional<dem::RollingModel> rolling_model;  ///< absent: EDEM standard
  double epsd_damping = 0.3;                       ///< rolling_model = epsd: viscous damping ratio

  bool on(const std::string& effect) const;
};

struct ParticleModel {
  std::string name;
  std::filesystem::path path;  ///< the model file (empty if built in code)
  std::string description;
  std::filesystem::path materials_path;
  MaterialLibrary materials = MaterialLibrary::paper_table1();
  MassBasis mass_basis = MassBasis::kSphereUnion;
  std::vector<ModelType> types;
  ModelEffects effects;

  /// The pill types the DEM sees: the model's types, or, with a height spread s, each type split
  /// into three height classes h(1 - s√3), h, h(1 + s√3) at number fractions 1/6, 2/3, 1/6 (the
  /// three-point Gauss–Hermite rule: the classes keep the height's mean and standard deviation),
  /// named NAME_short, NAME, NAME_tall, with mass fractions in proportion to their pill masses.
  /// Throws InputError for a spread on a type that is not a paper-rule cylinder.
  std::vector<ModelType> population() const;
  /// Clump templates of the population's types (filled by the paper rule or loaded), with the
  /// mass basis applied. `rays` sets the ray sampling of the union's mass properties.
  std::vector<dem::ClumpTypeSettings> clump_types(long rays = 20000) const;
  /// The DEM contact laws of every pill pair and pill–wall pair for `wall_materials`, with the
  /// absent effects removed. Throws InputError for a wall material the library lacks.
  std::vector<dem::PairContactOverride> pair_contacts(
      const std::vector<std::string>& wall_materials) const;
  /// Writes materials, clump types, rolling model and pair laws into `ws`.
  void configure(dem::WorldSettings& ws, const std::vector<std::string>& wall_materials,
                 long rays = 20000) const;
  /// Mixture for a factory: the population's type names and normalised mass fractions.
  std::vector<dem::MixtureEntry> mixture() const;
  /// A short description of the model and its effects, SI units.
  std::string summary() const;
};

/// Loads a model file; relative paths inside it (shapes, materials, clumps) are resolved against
/// the file's folder first, then against `data_dir` (the bundled data folder) when given.
ParticleModel load_model(const std::filesystem::path& path,
                         const std::filesystem::path& data_dir = {});
/// The same from a file's text (`path` names it in errors and anchors relative paths).
ParticleModel parse_model(const std::string& text, const std::filesystem::path& path,
                          const std::filesystem::path& data_dir = {});

/// A stable text of everything in a model that changes the physics (for cache keys and for
/// matching a rig's saved bed to the model that made it).
std::string model_fingerprint(const ParticleModel& model);

/// Replaces an effect from a `--set`-style assignment "effects.rolling_friction.pill=0.1" or
/// "effects.cohesion=off". "effects.size_distribution.TYPE=0.5" sets a type's mass fraction in a
/// model of several types (the others share the rest in their ratios). Throws InputError naming
/// `where` for unknown effects or bad values.
void set_model_effect(ParticleModel& model, const std::string& key, const std::string& value,
                      const std::string& where);

}  // namespace clumpkit
