#include "clumpkit/geometry/mass_properties.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>

namespace clumpkit {

namespace {

// Principal axes with a stable, reproducible choice of frame (see header).
void principal_frame(MassProperties& mp, double snap_deg, double degenerate) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(mp.inertia_tensor);
  Eigen::Vector3d ev = es.eigenvalues();  // ascending
  Eigen::Matrix3d ax = es.eigenvectors();
  const double scale = std::max(1e-300, ev.cwiseAbs().maxCoeff());
  const double gap01 = std::abs(ev[1] - ev[0]) / scale, gap12 = std::abs(ev[2] - ev[1]) / scale;
  const double cos_snap = std::cos(snap_deg * std::numbers::pi / 180.0);

  auto snap = [&](Eigen::Vector3d a) {
    Eigen::Index k;
    a.cwiseAbs().maxCoeff(&k);
    if (std::abs(a[k]) >= cos_snap) a = Eigen::Vector3d::Unit(k);
    if (a[k] < 0) a = -a;
    return a;
  };
  auto nearest_axis = [](const Eigen::Vector3d& n) {
    // Coordinate axis most orthogonal to n: used to seed the frame in a degenerate plane.
    Eigen::Index k;
    n.cwiseAbs().minCoeff(&k);
    return Eigen::Vector3d(Eigen::Vector3d::Unit(k));
  };

  if (gap01 < degenerate && gap12 < degenerate) {
    ax.setIdentity();
  } else if (gap01 < degenerate || gap12 < degenerate) {
    const int distinct = gap01 < degenerate ? 2 : 0;
    Eigen::Vector3d n = snap(ax.col(distinct));
    Eigen::Vector3d a = nearest_axis(n);
    a = (a - a.dot(n) * n).normalized();
    Eigen::Vector3d b = n.cross(a);
    if (distinct == 2) {
      ax.col(0) = a;
      ax.col(1) = b;
      ax.col(2) = n;
    } else {
      ax.col(0) = n;
      ax.col(1) = a;
      ax.col(2) = n.cross(a);
    }
  } else {
    for (int i = 0; i < 3; ++i) ax.col(i) = snap(ax.col(i));
    // Re-orthonormalise after snapping (snapping only happens when already nearly aligned).
    ax.col(0).normalize();
    ax.col(1) = (ax.col(1) - ax.col(1).dot(ax.col(0)) * ax.col(0)).normalized();
    ax.col(2) = ax.col(0).cross(ax.col(1));
  }
  if (ax.determinant() < 0) ax.col(2) = -ax.col(2);
  mp.principal_axes = ax;
  for (int i = 0; i < 3; ++i) ev[i] = ax.col(i).dot(mp.inertia_tensor * ax.col(i));
  mp.principal_moments = ev;
}

}  // namespace

MassProperties mass_properties(const Moments& m, double density, double snap_deg,
                               double degenerate) {
  MassProperties mp;
  mp.density = density;
  mp.volume = m.m0;
  mp.mass = density * m.m0;
  if (m.m0 <= 0.0) return mp;
  mp.center_of_mass = m.m1 / m.m0;
  // Second moment about the centre of mass, then I = ρ (tr(S) 1 − S).
  const Eigen::Matrix3d s = m.m2 - m.m0 * mp.center_of_mass * mp.center_of_mass.transpose();
  mp.inertia_tensor = density * (s.trace() * Eigen::Matrix3d::Identity() - s);
  mp.inertia_tensor = 0.5 * (mp.inertia_tensor + mp.inertia_tensor.transpose()).eval();
  principal_frame(mp, snap_deg, degenerate);
  return mp;
}

MassProperties mass_properties(const std::vector<Moments>& samples, double density,
                               MassPropertiesCI* ci) {
  MassProperties mp = mass_properties(mean_moments(samples), density);
  if (ci) {
    std::vector<double> vol, c[3], pm[3];
    for (const Moments& s : samples) {
      MassProperties r = mass_properties(s, density);
      vol.push_back(r.volume);
      for (int k = 0; k < 3; ++k) {
        c[k].push_back(r.center_of_mass[k]);
        // Moments about the mean frame's axes, so replicates are compared axis by axis.
        pm[k].push_back(mp.principal_axes.col(k).dot(r.inertia_tensor * mp.principal_axes.col(k)));
      }
    }
    ci->volume = estimate(vol).ci95;
    for (int k = 0; k < 3; ++k) {
      ci->center_of_mass[k] = estimate(c[k]).ci95;
      ci->principal_moments[k] = estimate(pm[k]).ci95;
    }
  }
  return mp;
}

MassProperties sphere_mass_properties(double r, double density) {
  MassProperties mp;
  mp.density = density;
  mp.volume = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  mp.mass = density * mp.volume;
  const double i = 0.4 * mp.mass * r * r;
  mp.inertia_tensor = i * Eigen::Matrix3d::Identity();
  mp.principal_moments.setConstant(i);
  return mp;
}

MassProperties cylinder_mass_properties(double r, double h, double density) {
  MassProperties mp;
  mp.density = density;
  mp.volume = std::numbers::pi * r * r * h;
  mp.mass = density * mp.volume;
  const double ixy = mp.mass * (3.0 * r * r + h * h) / 12.0, iz = 0.5 * mp.mass * r * r;
  mp.inertia_tensor = Eigen::Vector3d(ixy, ixy, iz).asDiagonal();
  principal_frame(mp, 0.5, 1e-3);
  return mp;
}

MassProperties box_mass_properties(const Eigen::Vector3d& l, double density) {
  MassProperties mp;
  mp.density = density;
  mp.volume = l.prod();
  mp.mass = density * mp.volume;
  const Eigen::Vector3d sq = l.cwiseProduct(l);
  Eigen::Vector3d i(sq[1] + sq[2], sq[0] + sq[2], sq[0] + sq[1]);
  i *= mp.mass / 12.0;
  mp.inertia_tensor = i.asDiagonal();
  principal_frame(mp, 0.5, 1e-3);
  return mp;
}

}  // namespace clumpkit
