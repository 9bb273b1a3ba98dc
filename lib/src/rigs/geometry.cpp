#include "clumpkit/rigs/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "clumpkit/mesh_io/write_mesh.hpp"

namespace clumpkit::rigs {

using Eigen::Vector3d;
using Tri = std::array<int, 3>;

double equal_area_polygon_radius(double r, int n) {
  // n-gon of circumradius R: area n R² sin(2π/n) / 2 = π r².
  return r * std::sqrt(2.0 * std::numbers::pi / (n * std::sin(2.0 * std::numbers::pi / n)));
}

double CupGeometry::volume() const {
  return std::numbers::pi * 0.25 * inner_diameter * inner_diameter * height;
}

namespace {

// Quad a-b-c-d (counter-clockwise seen from the side the normal points to).
void quad(dem::TriangleMesh& m, const Vector3d& a, const Vector3d& b, const Vector3d& c,
          const Vector3d& d) {
  const int i = int(m.vertices.size());
  m.vertices.insert(m.vertices.end(), {a, b, c, d});
  m.triangles.push_back({i, i + 1, i + 2});
  m.triangles.push_back({i, i + 2, i + 3});
}

// Lateral surface of a vertical prism (equal-area n-gon), normals inward when `inward`.
dem::TriangleMesh tube(double r, double z0, double z1, int n, bool inward) {
  dem::TriangleMesh m;
  const double rp = equal_area_polygon_radius(r, n);
  for (int k = 0; k < n; ++k) {
    const double a0 = 2.0 * std::numbers::pi * k / n, a1 = 2.0 * std::numbers::pi * (k + 1) / n;
    const Vector3d p0(rp * std::cos(a0), rp * std::sin(a0), z0);
    const Vector3d p1(rp * std::cos(a1), rp * std::sin(a1), z0);
    const Vector3d q0 = p0 + Vector3d(0, 0, z1 - z0), q1 = p1 + Vector3d(0, 0, z1 - z0);
    if (inward)
      quad(m, p0, q0, q1, p1);
    else
      quad(m, p0, p1, q1, q0);
  }
  return m;
}

// Disc (fan) at height z, normal +z when `up`.
dem::TriangleMesh disc(double r, double z, int n, bool up) {
  dem::TriangleMesh m;
  const double rp = equal_area_polygon_radius(r, n);
  m.vertices.push_back(Vector3d(0, 0, z));
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * std::numbers::pi * k / n;
    m.vertices.push_back(Vector3d(rp * std::cos(a), rp * std::sin(a), z));
  }
  for (int k = 0; k < n; ++k) {
    const int a = 1 + k, b = 1 + (k + 1) % n;
    m.triangles.push_back(up ? Tri{0, a, b} : Tri{0, b, a});
  }
  return m;
}

// Point of the wheel's xz cross-section at angle θ (from +x towards +z), radius r, depth y.
Vector3d polar(double r, double theta, double y, double zc) {
  return Vector3d(r * std::cos(theta), y, zc + r * std::sin(theta));
}

}  // namespace

dem::TriangleMesh cup_mesh(const CupGeometry& g) {
  dem::TriangleMesh m = tube(0.5 * g.inner_diameter, 0.0, g.height, g.segments, true);
  m.append(disc(0.5 * g.inner_diameter, 0.0, g.segments, true));
  return m;
}

dem::TriangleMesh scraper_mesh(double x0, double half_width, double z_low, double height) {
  dem::TriangleMesh m;
  quad(m, Vector3d(x0, -half_width, z_low), Vector3d(x0, half_width, z_low),
       Vector3d(x0, half_width, z_low + height), Vector3d(x0, -half_width, z_low + height));
  return m;
}

dem::TriangleMesh lifting_cylinder_mesh(const LiftingGeometry& g) {
  return tube(0.5 * g.inner_diameter, 0.0, g.height, g.segments, true);
}

TubeClearance tube_clearance(const std::vector<Vector3d>& centres, double radius, double br,
                             double bottom, double height) {
  TubeClearance c;
  const double reach = 1.5 * br;
  // Every centre is looked at until both are known (a pill in the footprint may come first).
  for (size_t i = 0; i < centres.size() && !(c.in_footprint && c.near_shell); ++i) {
    const Vector3d& x = centres[i];
    const double rho = x.head<2>().norm();
    c.in_footprint = c.in_footprint || (rho < radius + br && x.z() + 3.0 * br > bottom);
    c.near_shell = c.near_shell || (std::abs(rho - radius) < reach && x.z() + reach > bottom &&
                                    x.z() - reach < bottom + height);
  }
  return c;
}

dem::TriangleMesh plate_mesh(const LiftingGeometry& g) {
  return dem::make_plane(Vector3d::Zero(), Vector3d::UnitZ(), g.plate_side, g.plate_side, 1);
}

double WheelGeometry::pocket_area() const {
  const double annulus = std::numbers::pi * (outer_radius * outer_radius - hub_radius * hub_radius);
  const double vanes = pockets * vane_thickness * (outer_radius - hub_radius);
  return (annulus - vanes) / pockets;
}

double WheelGeometry::throat_z() const {
  const double rh = outer_radius + housing_gap;
  return axis_height + std::sqrt(rh * rh - 0.25 * hopper_opening * hopper_opening);
}

dem::TriangleMesh wheel_mesh(const WheelGeometry& g, double phase) {
  const double y0 = -0.5 * g.length, y1 = 0.5 * g.length;
  dem::TriangleMesh m;
  // Hub: a prism about the y axis (equal-area polygon), outward normals.
  const int n = g.arc_segments;
  const double rh = equal_area_polygon_radius(g.hub_radius, n);
  for (int k = 0; k < n; ++k) {
    const double a0 = 2.0 * std::numbers::pi * k / n, a1 = 2.0 * std::numbers::pi * (k + 1) / n;
    quad(m, polar(rh, a0, y0, g.axis_height), polar(rh, a0, y1, g.axis_height),
         polar(rh, a1, y1, g.axis_height), polar(rh, a1, y0, g.axis_height));
  }
  // Vanes: thin boxes from the hub to the outer radius (the hub face of each box is inside the
  // hub and omitted), outward normals.
  const double t = 0.5 * g.vane_thickness;
  for (int k = 0; k < g.pockets; ++k) {
    const double a = 2.0 * std::numbers::pi * k / g.pockets + phase;
    const Vector3d u(std::cos(a), 0, std::sin(a)), w(-std::sin(a), 0, std::cos(a));
    const Vector3d c(0, 0, g.axis_height);
    const double r0 = g.hub_radius * 0.9, r1 = g.outer_radius;
    auto P = [&](double r, double s, double y) {
      return Vector3d(c + r * u + s * w + Vector3d(0, y, 0));
    };
    quad(m, P(r0, t, y0), P(r0, t, y1), P(r1, t, y1), P(r1, t, y0));      // leading face
    quad(m, P(r0, -t, y0), P(r1, -t, y0), P(r1, -t, y1), P(r0, -t, y1));  // trailing face
    quad(m, P(r1, -t, y0), P(r1, t, y0), P(r1, t, y1), P(r1, -t, y1));    // tip
    quad(m, P(r0, -t, y0), P(r0, t, y0), P(r1, t, y0), P(r1, -t, y0));    // end y0
    quad(m, P(r0, -t, y1), P(r1, -t, y1), P(r1, t, y1), P(r0, t, y1));    // end y1
  }
  return m;
}

dem::TriangleMesh housing_mesh(const WheelGeometry& g) {
  const double rh = g.outer_radius + g.housing_gap;
  const double y0 = -0.5 * g.length, y1 = 0.5 * g.length;
  const double throat = std::acos(std::clamp(0.5 * g.hopper_opening / rh, 0.0, 1.0));
  const double outlet = std::numbers::pi / 6.0;  // the outlet spans ±30° about the bottom
  dem::TriangleMesh m;
  // Right arc: from the throat edge (angle `throat`) down to −90° + 30°; left arc mirrored.
  for (int side = 0; side < 2; ++side) {
    const double a_begin = throat, a_end = -0.5 * std::numbers::pi + outlet;
    const int n = std::max(4, int(g.arc_segments * (a_begin - a_end) / (2.0 * std::numbers::pi)));
    for (int k = 0; k < n; ++k) {
      double a0 = a_begin + (a_end - a_begin) * k / n,
             a1 = a_begin + (a_end - a_begin) * (k + 1) / n;
      if (side == 1) a0 = std::numbers::pi - a0, a1 = std::numbers::pi - a1;
      const Vector3d p0 = polar(rh, a0, y0, g.axis_height), p1 = polar(rh, a1, y0, g.axis_height);
      const Vector3d q0 = polar(rh, a0, y1, g.axis_height), q1 = polar(rh, a1, y1, g.axis_height);
      if (side == 0)
        quad(m, p0, q0, q1, p1);
      else
        quad(m, p0, p1, q1, q0);
    }
  }
  return m;
}

dem::TriangleMesh hopper_mesh(const WheelGeometry& g) {
  const double y0 = -0.5 * g.length, y1 = 0.5 * g.length;
  const double zt = g.throat_z();
  const double tan_a = std::tan(g.hopper_half_angle_deg * std::numbers::pi / 180.0);
  const double h = std::max(0.0, 0.5 * (g.hopper_top_width - g.hopper_opening)) / tan_a;
  const double w0 = 0.5 * g.hopper_opening, w1 = 0.5 * g.hopper_top_width;
  dem::TriangleMesh m;
  quad(m, Vector3d(w0, y0, zt), Vector3d(w1, y0, zt + h), Vector3d(w1, y1, zt + h),
       Vector3d(w0, y1, zt));
  quad(m, Vector3d(-w0, y0, zt), Vector3d(-w0, y1, zt), Vector3d(-w1, y1, zt + h),
       Vector3d(-w1, y0, zt + h));
  // Vertical extension above the cone so a tall feed stays in.
  const double hx = g.hopper_height;
  quad(m, Vector3d(w1, y0, zt + h), Vector3d(w1, y0, zt + h + hx), Vector3d(w1, y1, zt + h + hx),
       Vector3d(w1, y1, zt + h));
  quad(m, Vector3d(-w1, y0, zt + h), Vector3d(-w1, y1, zt + h), Vector3d(-w1, y1, zt + h + hx),
       Vector3d(-w1, y0, zt + h + hx));
  return m;
}

dem::TriangleMesh end_plates_mesh(const WheelGeometry& g) {
  const double zt = g.throat_z();
  const double tan_a = std::tan(g.hopper_half_angle_deg * std::numbers::pi / 180.0);
  const double h = std::max(0.0, 0.5 * (g.hopper_top_width - g.hopper_opening)) / tan_a;
  const double z0 = g.axis_height - g.outer_radius - g.housing_gap;
  const double z1 = zt + h + g.hopper_height;
  const double w = 0.5 * g.hopper_top_width;
  dem::TriangleMesh m;
  for (double y : {-0.5 * g.length, 0.5 * g.length}) {
    if (y < 0)
      quad(m, Vector3d(-w, y, z0), Vector3d(w, y, z0), Vector3d(w, y, z1), Vector3d(-w, y, z1));
    else
      quad(m, Vector3d(-w, y, z0), Vector3d(-w, y, z1), Vector3d(w, y, z1), Vector3d(w, y, z0));
  }
  return m;
}

std::vector<double> measured_pocket_areas(const WheelGeometry& g, int grid) {
  // Rasterise the annulus; a cell belongs to pocket k when its angle lies between vanes k and
  // k+1 and it is outside both vane slabs (|distance to the vane's mid-plane| > t/2) and the hub.
  std::vector<double> area(g.pockets, 0.0);
  const double R = g.outer_radius, h = 2.0 * R / grid;
  const double rhub = equal_area_polygon_radius(g.hub_radius, g.arc_segments);
  for (int i = 0; i < grid; ++i)
    for (int j = 0; j < grid; ++j) {
      const double x = -R + (i + 0.5) * h, z = -R + (j + 0.5) * h;
      const double r = std::hypot(x, z);
      if (r > R) continue;
      // Inside the hub polygon: compare with the polygon's radius at this angle.
      double a = std::atan2(z, x);
      if (a < 0) a += 2.0 * std::numbers::pi;
      const double seg = 2.0 * std::numbers::pi / g.arc_segments;
      const double local = std::fmod(a, seg) - 0.5 * seg;
      if (r * std::cos(local) < rhub * std::cos(0.5 * seg)) continue;
      bool in_vane = false;
      for (int k = 0; k < g.pockets && !in_vane; ++k) {
        const double b = 2.0 * std::numbers::pi * k / g.pockets;
        const double along = x * std::cos(b) + z * std::sin(b);
        const double across = -x * std::sin(b) + z * std::cos(b);
        in_vane = along > 0 && std::abs(across) <= 0.5 * g.vane_thickness;
      }
      if (in_vane) continue;
      const int k = int(a / (2.0 * std::numbers::pi / g.pockets)) % g.pockets;
      area[k] += h * h;
    }
  return area;
}

std::vector<std::string> write_rig_meshes(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const CupGeometry cup;
  const LiftingGeometry lift;
  const WheelGeometry wheel;
  const std::vector<std::pair<std::string, dem::TriangleMesh>> meshes = {
      {"cup", cup_mesh(cup)},
      {"scraper", scraper_mesh(-0.047, 0.055, cup.height, 0.06)},
      {"lifting_cylinder", lifting_cylinder_mesh(lift)},
      {"plate", plate_mesh(lift)},
      {"wheel", wheel_mesh(wheel)},
      {"housing", housing_mesh(wheel)},
      {"hopper", hopper_mesh(wheel)},
      {"end_plates", end_plates_mesh(wheel)}};
  std::vector<std::string> names;
  for (const auto& [name, m] : meshes) {
    clumpkit::TriangleMesh out;
    out.vertices = m.vertices;
    for (const auto& t : m.triangles) out.triangles.push_back(Eigen::Vector3i(t[0], t[1], t[2]));
    write_stl(out, dir / (name + ".stl"));
    names.push_back(name + ".stl");
  }
  return names;
}

double signed_volume(const dem::TriangleMesh& m) {
  double v = 0.0;
  for (const auto& t : m.triangles)
    v += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]]));
  return v / 6.0;
}

}  // namespace clumpkit::rigs
