#include "clumpkit/rigs/heap_angle.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "clumpkit/core/error.hpp"

namespace clumpkit::rigs {

namespace {

struct Projected {
  double u, z, r;
};

std::vector<Projected> project(const Spheres& s, const Eigen::Vector2d& axis, double azimuth) {
  const Eigen::Vector2d e(std::cos(azimuth), std::sin(azimuth));
  std::vector<Projected> p;
  p.reserve(s.size());
  for (const auto& sp : s)
    p.push_back({(sp.center.head<2>() - axis).dot(e), sp.center.z(), sp.radius});
  return p;
}

// Left and right ends of the connected run of chords at height z that contains u = 0 (or is
// nearest to it). Returns false when the row is empty.
bool row_edges(const std::vector<Projected>& p, double z, double gap, double& left, double& right) {
  std::vector<std::pair<double, double>> iv;
  for (const auto& s : p) {
    const double dz = z - s.z;
    if (std::abs(dz) >= s.r) continue;
    const double w = std::sqrt(s.r * s.r - dz * dz);
    iv.push_back({s.u - w, s.u + w});
  }
  if (iv.empty()) return false;
  std::sort(iv.begin(), iv.end());
  std::vector<std::pair<double, double>> runs;
  for (const auto& i : iv) {
    if (!runs.empty() && i.first <= runs.back().second + gap)
      runs.back().second = std::max(runs.back().second, i.second);
    else
      runs.push_back(i);
  }
  const std::pair<double, double>* best = nullptr;
  double best_d = 1e300;
  for (const auto& r : runs) {
    const double d =
        (r.first <= 0 && r.second >= 0) ? 0.0 : std::min(std::abs(r.first), std::abs(r.second));
    if (d < best_d) best_d = d, best = &r;
  }
  left = best->first;
  right = best->second;
  return true;
}

// Least squares u = a + c z over the edge points; outward slope c (positive for a heap).
FlankFit fit_flank(std::vector<Eigen::Vector2d> edge, double sign, double plate_z) {
  FlankFit f;
  f.edge = edge;
  f.points = int(edge.size());
  if (edge.size() < 3) return f;
  double sz = 0, su = 0, szz = 0, szu = 0;
  const double n = double(edge.size());
  for (auto& e : edge) {
    const double u = sign * e.x(), z = e.y() - plate_z;
    sz += z, su += u, szz += z * z, szu += z * u;
  }
  const double den = n * szz - sz * sz;
  if (!(den > 0)) return f;
  const double c = (n * szu - sz * su) / den;  // du/dz
  const double a = (su - c * sz) / n;
  double rss = 0;
  for (auto& e : edge) {
    const double r = sign * e.x() - (a + c * (e.y() - plate_z));
    rss += r * r;
  }
  f.slope = -c;  // the edge moves inwards with height: outward slope positive
  f.intercept = a;
  f.rms = std::sqrt(rss / n);
  // Angle from the horizontal: tan θ = dz/du = 1 / |c|.
  f.angle = std::atan2(1.0, std::max(-c, 1e-12));
  return f;
}

struct WindowResult {
  std::vector<HeapView> views;
  double mean = 0, left = 0, right = 0, stdev = 0, max_rms = 0;
};

WindowResult measure_window(const Spheres& s, const Eigen::Vector2d& axis, double height, double lo,
                            double hi, const HeapAngleOptions& o, double gap) {
  WindowResult w;
  std::vector<double> all;
  double sl = 0, sr = 0;
  int nl = 0, nr = 0;
  for (int v = 0; v < o.views; ++v) {
    HeapView hv;
    hv.azimuth = std::numbers::pi * v / o.views;
    const auto p = project(s, axis, hv.azimuth);
    std::vector<Eigen::Vector2d> el, er;
    for (int k = 0; k < o.rows; ++k) {
      const double z = o.plate_z + height * (lo + (hi - lo) * (k + 0.5) / o.rows);
      double l = 0, r = 0;
      if (!row_edges(p, z, gap, l, r)) continue;
      el.push_back({l, z});
      er.push_back({r, z});
    }
    hv.left = fit_flank(el, -1.0, o.plate_z);
    hv.right = fit_flank(er, 1.0, o.plate_z);
    for (const FlankFit* f : {&hv.left, &hv.right}) {
      if (f->points < 3) continue;
      all.push_back(f->angle);
      w.max_rms = std::max(w.max_rms, f->rms);
    }
    if (hv.left.points >= 3) sl += hv.left.angle, ++nl;
    if (hv.right.points >= 3) sr += hv.right.angle, ++nr;
    w.views.push_back(std::move(hv));
  }
  if (all.empty()) throw NumericalError("heap angle: no flank could be fitted");
  for (double a : all) w.mean += a / all.size();
  for (double a : all) w.stdev += (a - w.mean) * (a - w.mean);
  w.stdev = all.size() > 1 ? std::sqrt(w.stdev / (all.size() - 1)) : 0.0;
  w.left = nl ? sl / nl : w.mean;
  w.right = nr ? sr / nr : w.mean;
  return w;
}

}  // namespace

HeapAngle measure_heap_angle(const Spheres& s, const HeapAngleOptions& o) {
  if (s.empty()) throw NumericalError("heap angle: no spheres");
  double rmean = 0, top = o.plate_z;
  for (const auto& sp : s) {
    rmean += sp.radius / s.size();
    top = std::max(top, sp.center.z() + sp.radius);
  }
  const double height = top - o.plate_z;
  if (height < 4.0 * rmean)
    throw NumericalError("heap angle: the heap is only " + std::to_string(height * 1e3) +
                         " mm high (less than two sphere diameters): no cone to measure");
  const double gap = o.gap > 0 ? o.gap : 2.0 * rmean;

  // Axis: the column through the top part of the heap (the spheres in its upper 20 %), so a
  // lopsided skirt does not move it.
  Eigen::Vector2d axis = Eigen::Vector2d::Zero();
  double wsum = 0;
  for (const auto& sp : s)
    if (sp.center.z() > o.plate_z + 0.8 * height - sp.radius)
      axis += sp.center.head<2>(), wsum += 1;
  axis /= std::max(wsum, 1.0);

  HeapAngle h;
  h.height = height;
  h.axis = axis;
  h.window_low = o.window_low;
  h.window_high = o.window_high;
  const WindowResult main = measure_window(s, axis, height, o.window_low, o.window_high, o, gap);
  const WindowResult alt =
      measure_window(s, axis, height, o.alt_window_low, o.alt_window_high, o, gap);
  h.angle = main.mean;
  h.angle_left = main.left;
  h.angle_right = main.right;
  h.angle_std = main.stdev;
  h.max_rms = main.max_rms;
  h.alt_angle = alt.mean;
  h.views = main.views;

  // Height over radius: edge radius one diameter above the plate and at 95 % of the height.
  double rb = 0, rt = 0;
  int n = 0;
  for (int v = 0; v < o.views; ++v) {
    const auto p = project(s, axis, std::numbers::pi * v / o.views);
    double l0, r0, l1, r1;
    if (!row_edges(p, o.plate_z + 2.0 * rmean, gap, l0, r0)) continue;
    if (!row_edges(p, o.plate_z + 0.95 * height, gap, l1, r1)) continue;
    rb += 0.5 * (r0 - l0), rt += 0.5 * (r1 - l1), ++n;
  }
  if (n > 0) {
    h.base_radius = rb / n;
    const double top_r = rt / n;
    h.height_over_radius_angle =
        std::atan2(0.95 * height - 2.0 * rmean, std::max(h.base_radius - top_r, 1e-9));
  }
  return h;
}

std::vector<double> silhouette_profile(const Spheres& s, const Eigen::Vector2d& axis,
                                       double azimuth, double u_min, double u_max, int bins,
                                       double plate_z) {
  std::vector<double> z(bins, plate_z);
  const double du = (u_max - u_min) / bins;
  for (const auto& p : project(s, axis, azimuth)) {
    const int b0 = std::max(0, int(std::floor((p.u - p.r - u_min) / du)));
    const int b1 = std::min(bins - 1, int(std::floor((p.u + p.r - u_min) / du)));
    for (int b = b0; b <= b1; ++b) {
      const double u = u_min + (b + 0.5) * du, d = u - p.u;
      if (std::abs(d) < p.r) z[b] = std::max(z[b], p.z + std::sqrt(p.r * p.r - d * d));
    }
  }
  return z;
}

Spheres synthetic_cone(double base_radius, double angle, double r, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.25 * r, 0.25 * r);
  const double t = std::tan(angle);
  const double height = base_radius * t;  // of the centres' cone
  Spheres out;
  // Surface rings: centres on the cone, every ~r in height and around.
  for (double z = r; z < height; z += r) {
    const double rho = (height - z) / t;
    const int n = std::max(1, int(2.0 * std::numbers::pi * rho / r));
    const double phase = std::uniform_real_distribution<double>(0, 2 * std::numbers::pi)(rng);
    for (int k = 0; k < n; ++k) {
      const double a = phase + 2.0 * std::numbers::pi * k / n;
      out.push_back({Eigen::Vector3d(rho * std::cos(a), rho * std::sin(a), z), r});
    }
  }
  // Interior: a jittered lattice with centres inside the cone.
  const double h = 1.6 * r;
  for (double z = r; z < height; z += h)
    for (double x = -base_radius; x <= base_radius; x += h)
      for (double y = -base_radius; y <= base_radius; y += h) {
        const Eigen::Vector3d c(x + jitter(rng), y + jitter(rng), z);
        if (std::hypot(c.x(), c.y()) < (height - z) / t - 0.5 * r) out.push_back({c, r});
      }
  return out;
}

}  // namespace clumpkit::rigs
