#pragma once
// Small scenes shared by the DEM tests.
#include <cmath>
#include <numbers>

#include "clumpkit/dem/world.hpp"
#include "clumpkit/geometry/mass_properties.hpp"

namespace clumpkit::dem::test {

/// A single-sphere clump type with exact mass properties.
inline ClumpTypeSettings sphere_type(const std::string& name, double radius, double density,
                                     const std::string& material = "pill") {
  ClumpTypeSettings t;
  t.name = name;
  t.clump.name = name;
  t.clump.spheres = {Sphere{Eigen::Vector3d::Zero(), radius}};
  t.clump.mass = sphere_mass_properties(radius, density);
  t.material = material;
  return t;
}

/// A clump from spheres with given (not sampled) mass and principal moments, in its
/// principal frame. For tests that need a rigid body of known inertia.
inline ClumpTypeSettings clump_type(const std::string& name, const Spheres& spheres, double mass,
                                    const Eigen::Vector3d& moments,
                                    const std::string& material = "pill") {
  ClumpTypeSettings t;
  t.name = name;
  t.clump.name = name;
  t.clump.spheres = spheres;
  t.clump.mass.mass = mass;
  t.clump.mass.density = 1.0;
  t.clump.mass.volume = mass;
  t.clump.mass.inertia_tensor = moments.asDiagonal();
  t.clump.mass.principal_moments = moments;
  return t;
}

/// A pill-like material library with one interaction whose effects the test chooses.
inline MaterialLibrary test_materials(double e, double mu_s, double mu_r) {
  MaterialLibrary lib = MaterialLibrary::paper_table1();
  lib.set_interaction("pill", "pill", {e, mu_s, mu_r});
  lib.set_interaction("pill", "galvanized_steel", {e, mu_s, mu_r});
  return lib;
}

inline WallSettings floor_wall(double size, int divisions, double z = 0.0,
                               const std::string& material = "galvanized_steel") {
  WallSettings w;
  w.name = "floor";
  w.mesh = make_plane(Eigen::Vector3d(0, 0, z), Eigen::Vector3d::UnitZ(), size, size, divisions);
  w.material = material;
  return w;
}

}  // namespace clumpkit::dem::test
