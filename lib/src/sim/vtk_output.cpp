#include "clumpkit/sim/vtk_output.hpp"

#include <sstream>

namespace clumpkit::sim {

namespace {
void header(std::ostringstream& s) {
  s.precision(9);
  s << "<?xml version=\"1.0\"?>\n"
       "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n";
}
}  // namespace

std::string particles_vtp(const dem::World& w) {
  std::ostringstream s;
  header(s);
  const auto& x = w.sphere_positions();
  const auto& r = w.sphere_radii();
  const auto& c = w.sphere_clumps();
  const size_t n = x.size();
  s << "<Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"" << n << "\">\n";
  s << "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& p : x) s << p[0] << " " << p[1] << " " << p[2] << "\n";
  s << "</DataArray></Points>\n<PointData Scalars=\"radius\">\n";
  s << "<DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">\n";
  for (double v : r) s << v << "\n";
  s << "</DataArray>\n<DataArray type=\"Int32\" Name=\"clump_id\" format=\"ascii\">\n";
  for (int v : c) s << v << "\n";
  s << "</DataArray>\n<DataArray type=\"Int32\" Name=\"clump_type\" format=\"ascii\">\n";
  for (int v : c) s << w.clump_type_of(v) << "\n";
  s << "</DataArray>\n<DataArray type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\" "
       "format=\"ascii\">\n";
  for (size_t i = 0; i < n; ++i) {
    // Velocity of the sphere centre: v + ω × (x_sphere − x_com).
    const int k = c[i];
    const Eigen::Vector3d v = w.velocities()[k] + w.omega_world(k).cross(x[i] - w.positions()[k]);
    s << v[0] << " " << v[1] << " " << v[2] << "\n";
  }
  s << "</DataArray>\n</PointData>\n";
  s << "<Verts><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (size_t i = 0; i < n; ++i) s << i << "\n";
  s << "</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (size_t i = 0; i < n; ++i) s << i + 1 << "\n";
  s << "</DataArray></Verts>\n</Piece>\n</PolyData>\n</VTKFile>\n";
  return s.str();
}

namespace {
// Walls first .. last - 1 as one PolyData; the `wall_id` cell array gives each triangle's wall.
std::string walls_range_vtp(const dem::World& w, int first, int last) {
  std::ostringstream s;
  header(s);
  size_t nv = 0, nt = 0;
  for (int k = first; k < last; ++k) {
    nv += w.wall_vertices(k).size();
    nt += w.wall_settings(k).mesh.triangles.size();
  }
  s << "<Piece NumberOfPoints=\"" << nv << "\" NumberOfPolys=\"" << nt << "\">\n";
  s << "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (int k = first; k < last; ++k)
    for (const auto& p : w.wall_vertices(k)) s << p[0] << " " << p[1] << " " << p[2] << "\n";
  s << "</DataArray></Points>\n<CellData Scalars=\"wall_id\">\n"
       "<DataArray type=\"Int32\" Name=\"wall_id\" format=\"ascii\">\n";
  for (int k = first; k < last; ++k)
    for (size_t t = 0; t < w.wall_settings(k).mesh.triangles.size(); ++t) s << k << "\n";
  s << "</DataArray>\n</CellData>\n<Polys><DataArray type=\"Int64\" Name=\"connectivity\" "
       "format=\"ascii\">\n";
  size_t base = 0;
  for (int k = first; k < last; ++k) {
    for (const auto& t : w.wall_settings(k).mesh.triangles)
      s << base + t[0] << " " << base + t[1] << " " << base + t[2] << "\n";
    base += w.wall_vertices(k).size();
  }
  s << "</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (size_t t = 0; t < nt; ++t) s << 3 * (t + 1) << "\n";
  s << "</DataArray></Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n";
  return s.str();
}
}  // namespace

std::string walls_vtp(const dem::World& w) {
  return walls_range_vtp(w, 0, w.wall_count());
}

std::string wall_vtp(const dem::World& w, int wall) {
  return walls_range_vtp(w, wall, wall + 1);
}

std::string pvd(const std::vector<std::pair<double, std::string>>& frames) {
  std::ostringstream s;
  s.precision(9);
  s << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (const auto& [t, f] : frames)
    s << "<DataSet timestep=\"" << t << "\" part=\"0\" file=\"" << f << "\"/>\n";
  s << "</Collection>\n</VTKFile>\n";
  return s.str();
}

}  // namespace clumpkit::sim
