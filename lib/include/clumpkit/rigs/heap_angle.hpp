#pragma once
/// Angle of repose of a heap on a plate, measured as the paper's image processing does: from
/// side-view silhouettes (SPEC §7). For each viewing direction the spheres are projected onto
/// the vertical plane facing the viewer; in each horizontal row (height z) the silhouette is the
/// union of the spheres' chords, and the heap's edge in that row is the end of the connected
/// run of chords that contains the heap's axis (detached pills are ignored). A straight line is
/// fitted to each flank's edge points inside the fit window (a band of heights, a fraction of
/// the heap height, excluding toe and apex). Several viewing directions are averaged.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "clumpkit/geometry/sphere.hpp"

namespace clumpkit::rigs {

struct HeapAngleOptions {
  int views = 8;            ///< viewing azimuths spread over 180°; each gives two flanks
  double window_low = 0.2;  ///< fit window, fraction of the heap height
  double window_high = 0.8;
  int rows = 40;         ///< rows sampled inside the window
  double plate_z = 0.0;  ///< z of the plate, m
  /// Chords separated by more than this gap are not connected, m; 0 = one mean sphere diameter.
  double gap = 0.0;
  /// Second window for the robustness figure (SPEC §7 compares 20–80 % with 30–70 %).
  double alt_window_low = 0.3;
  double alt_window_high = 0.7;
};

struct FlankFit {
  double angle = 0.0;      ///< rad, from the horizontal
  double slope = 0.0;      ///< du/dz of the edge (outward positive)
  double intercept = 0.0;  ///< u at z = plate, m
  double rms = 0.0;        ///< RMS horizontal residual of the edge points, m
  int points = 0;
  std::vector<Eigen::Vector2d> edge;  ///< (u, z) edge points used, m
};

struct HeapView {
  double azimuth = 0.0;  ///< rad, direction of the view's horizontal axis u
  FlankFit left, right;  ///< left: u < axis
};

struct HeapAngle {
  double angle = 0.0;        ///< rad, mean of all flanks of all views
  double angle_left = 0.0;   ///< rad, mean of the left flanks
  double angle_right = 0.0;  ///< rad
  double angle_std = 0.0;    ///< rad, standard deviation over the flanks
  double alt_angle = 0.0;    ///< rad, the same in the alternative window
  double height = 0.0;       ///< heap height above the plate, m
  double base_radius = 0.0;  ///< mean edge radius one sphere diameter above the plate, m
  double height_over_radius_angle = 0.0;  ///< rad, atan(height / (base_radius − top radius))
  double max_rms = 0.0;                   ///< worst flank RMS residual, m
  Eigen::Vector2d axis = Eigen::Vector2d::Zero();  ///< heap axis (x, y), m
  std::vector<HeapView> views;
  double window_low = 0.0, window_high = 0.0;
};

/// Throws NumericalError when there is no heap (height below two sphere diameters).
HeapAngle measure_heap_angle(const Spheres& spheres, const HeapAngleOptions& options = {});

/// Silhouette profile z(u) of one view (top of the projected spheres on a grid of `bins`
/// columns over [u_min, u_max]); columns with nothing hold the plate height.
std::vector<double> silhouette_profile(const Spheres& spheres, const Eigen::Vector2d& axis,
                                       double azimuth, double u_min, double u_max, int bins,
                                       double plate_z);

/// Spheres of a right circular cone of the given base radius and angle standing on z = 0 (a
/// random close packing with centres inside the cone shrunk by r): for tests.
Spheres synthetic_cone(double base_radius, double angle, double sphere_radius, unsigned seed);

}  // namespace clumpkit::rigs
