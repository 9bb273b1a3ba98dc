#pragma once
/// Pictures of rig results (PNG through libpng) and VTK files for ParaView.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "clumpkit/dem/wall.hpp"
#include "clumpkit/geometry/sphere.hpp"
#include "clumpkit/rigs/heap_angle.hpp"

namespace clumpkit::rigs {

/// An RGB raster with the few drawing operations the plots need.
class Canvas {
 public:
  Canvas(int width, int height, std::uint32_t background = 0xffffff);
  int width() const { return w_; }
  int height() const { return h_; }
  void pixel(int x, int y, std::uint32_t rgb);
  std::uint32_t at(int x, int y) const;
  void line(double x0, double y0, double x1, double y1, std::uint32_t rgb, int thickness = 1);
  void fill_rect(int x0, int y0, int x1, int y1, std::uint32_t rgb);
  /// Text in a built-in 5×7 font (digits, letters, ". - = ( ) / % : °" as 'o'), scaled by `scale`.
  void text(int x, int y, const std::string& s, std::uint32_t rgb, int scale = 2);
  /// Writes a PNG atomically; InputError naming the path on failure.
  void save_png(const std::filesystem::path& path) const;

 private:
  int w_, h_;
  std::vector<std::uint8_t> rgb_;
};

/// Side view (view 0) of the heap: silhouette in grey, fitted flank lines in red, fit window
/// band, angles written on it.
void heap_picture(const std::filesystem::path& path, const Spheres& spheres, const HeapAngle& h,
                  double plate_z = 0.0);

/// Cumulative discharged mass against time, one curve per label (e.g. "15 rpm").
struct Curve {
  std::string label;
  std::vector<double> t, m;  ///< s, kg
};
void curve_picture(const std::filesystem::path& path, const std::vector<Curve>& curves,
                   const std::string& x_label, const std::string& y_label);

}  // namespace clumpkit::rigs
