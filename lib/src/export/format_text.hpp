#pragma once
// Shared text pieces of the export formats: exact number formatting and the comment block that
// records the frame transform and the union's mass properties.
#include <string>
#include <string_view>
#include <vector>

#include "clumpkit/export/exporter.hpp"

namespace clumpkit::export_detail {

/// Shortest text that reads back to the same double ("%.17g"): exports round-trip exactly.
std::string num(double v);

/// Comment lines, each starting with `prefix` ("# ", "// "), stating the frame, the transform to
/// the source frame, the union's density, volume, mass, centre of mass, inertia tensor and
/// principal moments with units, and the provenance. Ends with a newline.
std::string provenance_block(const ClumpTemplate& c, std::string_view format,
                             std::string_view prefix);

/// The union's mass split over the spheres in proportion to sphere volume (r^3); sums to
/// c.mass.mass. Formats that need per-sphere masses (LAMMPS) use it; the body's mass and inertia
/// still come from the union, not from these.
std::vector<double> volume_weighted_masses(const ClumpTemplate& c);

/// Throws InputError when the template is not in its centroid-principal frame (centre of mass
/// farther than 1e-4 of the clump's size from the origin, or an off-diagonal inertia component
/// above 1e-3 of the largest moment): formats that assume that frame cannot hold it.
void require_principal_frame(const ClumpTemplate& c, std::string_view format);

/// The inertia tensor the DEM formats get: diag(principal moments). The template frame is the
/// principal frame by definition; its sampled off-diagonal residuals (checked to be below 1e-3 of
/// the largest moment by require_principal_frame, and recorded in the comment block) are not
/// passed on, because for near-equal moments (any axisymmetric pill) they would make the DEM code
/// rotate the body frame arbitrarily within the degenerate plane.
Eigen::Matrix3d principal_inertia(const ClumpTemplate& c);

// The renderers, one per file.
std::vector<ExportFile> render_liggghts(const ClumpTemplate& c, const ExportSettings& s);
std::vector<ExportFile> render_lammps(const ClumpTemplate& c, const ExportSettings& s);
std::vector<ExportFile> render_edem(const ClumpTemplate& c, const ExportSettings& s);
std::vector<ExportFile> render_yade(const ClumpTemplate& c, const ExportSettings& s);
std::vector<ExportFile> render_mercurydpm(const ClumpTemplate& c, const ExportSettings& s);
std::vector<ExportFile> render_deme(const ClumpTemplate& c, const ExportSettings& s);
std::vector<ExportFile> render_vtk(const ClumpTemplate& c, const ExportSettings& s);

}  // namespace clumpkit::export_detail
