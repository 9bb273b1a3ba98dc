#pragma once
/// Parametric wall meshes of the paper's rigs (SPEC §7), generated in code, metres, z up.
/// Containers are oriented with normals pointing into the space the pills occupy (the DEM's
/// contact is two-sided; the orientation matters for ParaView and for the volume checks).
/// Circles are tessellated with the equal-area polygon, so the faceted cup holds exactly the
/// nominal volume.
#include <filesystem>
#include <string>
#include <vector>

#include "clumpkit/dem/wall.hpp"

namespace clumpkit::rigs {

/// Radius of the regular n-gon whose area equals that of a circle of radius r.
double equal_area_polygon_radius(double r, int segments);

/// Bulk-density measuring cylinder (organic glass, 0.26 L: inner D 70 mm, H 67.6 mm, assumed).
struct CupGeometry {
  double inner_diameter = 0.070;  ///< m
  double height = 0.0676;         ///< m; the rim is at z = height, the floor at z = 0
  int segments = 64;
  double volume() const;  ///< m^3, π D² H / 4
};
/// Lateral surface and floor, normals inward.
dem::TriangleMesh cup_mesh(const CupGeometry& g);
/// A flat scraper blade (two-sided rectangle in the plane x = x0), spanning y in ±half_width and
/// z in [z_low, z_low + height]; it strikes off everything above the rim when moved along +x.
dem::TriangleMesh scraper_mesh(double x0, double half_width, double z_low, double height);

/// Angle-of-repose rig: lifting cylinder (ABS, D 65.7 mm × H 150 mm, open both ends) standing on
/// a square plate (galvanized steel, 500 mm side) at z = 0.
struct LiftingGeometry {
  double inner_diameter = 0.0657;  ///< m
  double height = 0.150;           ///< m
  double plate_side = 0.500;       ///< m
  int segments = 64;
};
dem::TriangleMesh lifting_cylinder_mesh(const LiftingGeometry& g);
dem::TriangleMesh plate_mesh(const LiftingGeometry& g);

/// Where the pills stand against the lifting tube (inner radius `radius`, its bottom edge at
/// `bottom`, `height` tall), from the clumps' centres and their largest bounding radius `br`.
struct TubeClearance {
  /// Some centre within `radius + br` of the axis lies less than 3 br below the bottom edge or
  /// above it: the tube has not yet cleared the heap.
  bool in_footprint = false;
  /// Some centre lies within 1.5 br of the shell radially, at a height within 1.5 br of the
  /// tube's extent: the tube may touch it.
  bool near_shell = false;
};
TubeClearance tube_clearance(const std::vector<Eigen::Vector3d>& centres, double radius, double br,
                             double bottom, double height);

/// Discharge rig: a pocket wheel turning about the y axis, fed from a hopper above and closed
/// by a housing around its upper half-turn; pills leave through the open lower side.
/// The rig is a slice of `length` along the wheel axis (y ∈ ±length/2) between two end plates;
/// the paper's pockets are 100 mm long (SPEC §7).
struct WheelGeometry {
  double outer_radius = 0.100;    ///< m (assumed)
  double hub_radius = 0.050;      ///< m (assumed)
  double vane_thickness = 0.003;  ///< m (assumed)
  int pockets = 8;
  double length = 0.100;                ///< m, along the axis; < 0.1 m = a documented slice
  double axis_height = 0.0;             ///< z of the axis, m
  double housing_gap = 0.002;           ///< radial clearance between vane tips and housing, m
  double hopper_opening = 0.080;        ///< width of the hopper's throat above the wheel, m
  double hopper_half_angle_deg = 35.0;  ///< hopper wall angle from the vertical, deg
  double hopper_top_width = 0.400;      ///< m (the paper's factory box is 400 mm long)
  double hopper_height = 0.200;         ///< m above the throat
  int arc_segments = 48;
  /// Free cross-section area of one pocket (annulus minus vanes, / pockets), m².
  double pocket_area() const;
  double pocket_volume() const { return pocket_area() * length; }
  double throat_z() const;  ///< z of the hopper throat (top of the housing)
};
/// The wheel: hub cylinder and `pockets` vanes (boxes), axis along y through (0, 0, axis_height).
/// Vane k is centred at angle 2πk/pockets + phase, measured from +x towards +z.
dem::TriangleMesh wheel_mesh(const WheelGeometry& g, double phase = 0.0);
/// The housing arc (upper half around the wheel, leaving the throat open), the hopper's two
/// inclined walls and two vertical end plates at y = ±length/2.
dem::TriangleMesh housing_mesh(const WheelGeometry& g);
dem::TriangleMesh hopper_mesh(const WheelGeometry& g);
dem::TriangleMesh end_plates_mesh(const WheelGeometry& g);
/// Free cross-section area of each pocket of the tessellated wheel, measured on a fine grid
/// (a check of the mesh against pocket_area()), m².
std::vector<double> measured_pocket_areas(const WheelGeometry& g, int grid = 400);

/// Writes every rig's walls at paper size as binary STL files (metres) into `dir`
/// (cup, scraper, lifting_cylinder, plate, wheel, housing, hopper, end_plates); returns the
/// names written.
std::vector<std::string> write_rig_meshes(const std::filesystem::path& dir);

/// Enclosed volume of a closed triangle mesh (divergence theorem; sign follows the orientation).
double signed_volume(const dem::TriangleMesh& m);

}  // namespace clumpkit::rigs
