// VTK XML PolyData (.vtp): one vertex per sphere centre with `radius` and `diameter` point
// arrays (ParaView: Glyph filter, sphere glyph, scale by `diameter`, factor 1), and the union's
// mass properties and frame transform as FieldData.
#include <fmt/format.h>

#include "format_text.hpp"

namespace clumpkit::export_detail {

namespace {
// "--" may not appear inside an XML comment.
std::string xml_comment_safe(std::string s) {
  for (size_t i = s.find("--"); i != std::string::npos; i = s.find("--", i)) s.replace(i, 2, "- ");
  return s;
}
std::string field(const char* name, const std::vector<double>& v) {
  std::string o = fmt::format(
      "      <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" "
      "NumberOfTuples=\"1\" format=\"ascii\">",
      name, v.size());
  for (size_t i = 0; i < v.size(); ++i) o += fmt::format("{}{}", i ? " " : "", num(v[i]));
  return o + "</DataArray>\n";
}
}  // namespace

std::vector<ExportFile> render_vtk(const ClumpTemplate& c, const ExportSettings& s) {
  const size_t n = c.spheres.size();
  const MassProperties& m = c.mass;
  std::string o = "<?xml version=\"1.0\"?>\n<!--\n";
  o += xml_comment_safe(provenance_block(c, "vtk", "  "));
  o += "-->\n";
  o += "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n";
  o += "  <PolyData>\n    <FieldData>\n";
  o += field("density_kg_m3", {m.density});
  o += field("volume_m3", {m.volume});
  o += field("mass_kg", {m.mass});
  o += field("center_of_mass_m", {m.center_of_mass[0], m.center_of_mass[1], m.center_of_mass[2]});
  o += field("principal_moments_kg_m2",
             {m.principal_moments[0], m.principal_moments[1], m.principal_moments[2]});
  std::vector<double> rot, inertia;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      rot.push_back(c.rotation(i, j));
      inertia.push_back(m.inertia_tensor(i, j));
    }
  o += field("inertia_tensor_kg_m2", inertia);
  o += field("rotation_to_source", rot);
  o += field("translation_to_source_m", {c.translation[0], c.translation[1], c.translation[2]});
  o += "    </FieldData>\n";
  o += fmt::format(
      "    <Piece NumberOfPoints=\"{0}\" NumberOfVerts=\"{0}\" NumberOfLines=\"0\" "
      "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n",
      n);
  o += "      <PointData Scalars=\"radius\">\n";
  o += "        <DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">\n";
  for (const Sphere& sp : c.spheres) o += fmt::format("          {}\n", num(sp.radius));
  o += "        </DataArray>\n";
  o += "        <DataArray type=\"Float64\" Name=\"diameter\" format=\"ascii\">\n";
  for (const Sphere& sp : c.spheres) o += fmt::format("          {}\n", num(2.0 * sp.radius));
  o += "        </DataArray>\n      </PointData>\n";
  o += "      <Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" "
       "format=\"ascii\">\n";
  for (const Sphere& sp : c.spheres)
    o += fmt::format("          {} {} {}\n", num(sp.center[0]), num(sp.center[1]),
                     num(sp.center[2]));
  o += "        </DataArray>\n      </Points>\n      <Verts>\n";
  o += "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n         ";
  for (size_t i = 0; i < n; ++i) o += fmt::format(" {}", i);
  o += "\n        </DataArray>\n";
  o += "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n         ";
  for (size_t i = 0; i < n; ++i) o += fmt::format(" {}", i + 1);
  o += "\n        </DataArray>\n      </Verts>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  return {{export_base_name(c, s) + ".vtp", o}};
}

}  // namespace clumpkit::export_detail
