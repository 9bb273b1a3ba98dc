#include "clumpkit/rigs/pictures.hpp"

#include <fmt/format.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"

namespace clumpkit::rigs {

namespace {

// A 5×7 bitmap font: each glyph is 7 rows of 5 columns, '#' = ink. Letters are drawn upper case.
const std::map<char, std::array<const char*, 7>>& font() {
  static const std::map<char, std::array<const char*, 7>> f = {
      {'0', {" ### ", "#   #", "#  ##", "# # #", "##  #", "#   #", " ### "}},
      {'1', {"  #  ", " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "}},
      {'2', {" ### ", "#   #", "    #", "   # ", "  #  ", " #   ", "#####"}},
      {'3', {"#####", "   # ", "  #  ", "   # ", "    #", "#   #", " ### "}},
      {'4', {"   # ", "  ## ", " # # ", "#  # ", "#####", "   # ", "   # "}},
      {'5', {"#####", "#    ", "#### ", "    #", "    #", "#   #", " ### "}},
      {'6', {"  ## ", " #   ", "#    ", "#### ", "#   #", "#   #", " ### "}},
      {'7', {"#####", "    #", "   # ", "  #  ", " #   ", " #   ", " #   "}},
      {'8', {" ### ", "#   #", "#   #", " ### ", "#   #", "#   #", " ### "}},
      {'9', {" ### ", "#   #", "#   #", " ####", "    #", "   # ", " ##  "}},
      {'.', {"     ", "     ", "     ", "     ", "     ", " ##  ", " ##  "}},
      {'-', {"     ", "     ", "     ", "#####", "     ", "     ", "     "}},
      {'=', {"     ", "     ", "#####", "     ", "#####", "     ", "     "}},
      {'(', {"   # ", "  #  ", " #   ", " #   ", " #   ", "  #  ", "   # "}},
      {')', {" #   ", "  #  ", "   # ", "   # ", "   # ", "  #  ", " #   "}},
      {'/', {"     ", "    #", "   # ", "  #  ", " #   ", "#    ", "     "}},
      {'%', {"##   ", "##  #", "   # ", "  #  ", " #   ", "#  ##", "   ##"}},
      {':', {"     ", " ##  ", " ##  ", "     ", " ##  ", " ##  ", "     "}},
      {'+', {"     ", "  #  ", "  #  ", "#####", "  #  ", "  #  ", "     "}},
      {'A', {" ### ", "#   #", "#   #", "#####", "#   #", "#   #", "#   #"}},
      {'B', {"#### ", "#   #", "#   #", "#### ", "#   #", "#   #", "#### "}},
      {'C', {" ### ", "#   #", "#    ", "#    ", "#    ", "#   #", " ### "}},
      {'D', {"#### ", "#   #", "#   #", "#   #", "#   #", "#   #", "#### "}},
      {'E', {"#####", "#    ", "#    ", "#### ", "#    ", "#    ", "#####"}},
      {'F', {"#####", "#    ", "#    ", "#### ", "#    ", "#    ", "#    "}},
      {'G', {" ### ", "#   #", "#    ", "# ###", "#   #", "#   #", " ####"}},
      {'H', {"#   #", "#   #", "#   #", "#####", "#   #", "#   #", "#   #"}},
      {'I', {" ### ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "}},
      {'J', {"  ###", "   # ", "   # ", "   # ", "   # ", "#  # ", " ##  "}},
      {'K', {"#   #", "#  # ", "# #  ", "##   ", "# #  ", "#  # ", "#   #"}},
      {'L', {"#    ", "#    ", "#    ", "#    ", "#    ", "#    ", "#####"}},
      {'M', {"#   #", "## ##", "# # #", "# # #", "#   #", "#   #", "#   #"}},
      {'N', {"#   #", "#   #", "##  #", "# # #", "#  ##", "#   #", "#   #"}},
      {'O', {" ### ", "#   #", "#   #", "#   #", "#   #", "#   #", " ### "}},
      {'P', {"#### ", "#   #", "#   #", "#### ", "#    ", "#    ", "#    "}},
      {'Q', {" ### ", "#   #", "#   #", "#   #", "# # #", "#  # ", " ## #"}},
      {'R', {"#### ", "#   #", "#   #", "#### ", "# #  ", "#  # ", "#   #"}},
      {'S', {" ####", "#    ", "#    ", " ### ", "    #", "    #", "#### "}},
      {'T', {"#####", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  "}},
      {'U', {"#   #", "#   #", "#   #", "#   #", "#   #", "#   #", " ### "}},
      {'V', {"#   #", "#   #", "#   #", "#   #", "#   #", " # # ", "  #  "}},
      {'W', {"#   #", "#   #", "#   #", "# # #", "# # #", "# # #", " # # "}},
      {'X', {"#   #", "#   #", " # # ", "  #  ", " # # ", "#   #", "#   #"}},
      {'Y', {"#   #", "#   #", " # # ", "  #  ", "  #  ", "  #  ", "  #  "}},
      {'Z', {"#####", "    #", "   # ", "  #  ", " #   ", "#    ", "#####"}},
  };
  return f;
}

std::uint8_t channel(std::uint32_t rgb, int shift) {
  return std::uint8_t((rgb >> shift) & 0xff);
}

}  // namespace

Canvas::Canvas(int width, int height, std::uint32_t bg)
    : w_(width), h_(height), rgb_(3 * width * height) {
  for (int i = 0; i < w_ * h_; ++i) {
    rgb_[3 * i] = channel(bg, 16);
    rgb_[3 * i + 1] = channel(bg, 8);
    rgb_[3 * i + 2] = channel(bg, 0);
  }
}

void Canvas::pixel(int x, int y, std::uint32_t rgb) {
  if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
  const int i = 3 * (y * w_ + x);
  rgb_[i] = channel(rgb, 16), rgb_[i + 1] = channel(rgb, 8), rgb_[i + 2] = channel(rgb, 0);
}

std::uint32_t Canvas::at(int x, int y) const {
  const int i = 3 * (y * w_ + x);
  return (std::uint32_t(rgb_[i]) << 16) | (std::uint32_t(rgb_[i + 1]) << 8) | rgb_[i + 2];
}

void Canvas::line(double x0, double y0, double x1, double y1, std::uint32_t rgb, int thickness) {
  const int n = int(std::ceil(std::max(std::abs(x1 - x0), std::abs(y1 - y0)))) + 1;
  for (int k = 0; k <= n; ++k) {
    const double t = double(k) / n;
    const int x = int(std::lround(x0 + t * (x1 - x0))), y = int(std::lround(y0 + t * (y1 - y0)));
    for (int dx = -(thickness / 2); dx <= thickness / 2; ++dx)
      for (int dy = -(thickness / 2); dy <= thickness / 2; ++dy) pixel(x + dx, y + dy, rgb);
  }
}

void Canvas::fill_rect(int x0, int y0, int x1, int y1, std::uint32_t rgb) {
  for (int y = std::max(0, y0); y < std::min(h_, y1); ++y)
    for (int x = std::max(0, x0); x < std::min(w_, x1); ++x) pixel(x, y, rgb);
}

void Canvas::text(int x, int y, const std::string& s, std::uint32_t rgb, int scale) {
  const auto& f = font();
  for (char ch : s) {
    const char u = char(std::toupper(static_cast<unsigned char>(ch)));
    const auto it = f.find(u);
    if (it != f.end())
      for (int r = 0; r < 7; ++r)
        for (int col = 0; col < 5; ++col)
          if (it->second[r][col] == '#')
            fill_rect(x + col * scale, y + r * scale, x + (col + 1) * scale, y + (r + 1) * scale,
                      rgb);
    x += 6 * scale;
  }
}

void Canvas::save_png(const std::filesystem::path& path) const {
  // libpng writes to a FILE*; render into memory first, then write atomically.
  std::string buffer;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) throw InputError(path.string(), "", "cannot initialise libpng");
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw InputError(path.string(), "", "libpng failed to encode the image");
  }
  png_set_write_fn(
      png, &buffer,
      [](png_structp p, png_bytep data, png_size_t n) {
        static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<char*>(data), n);
      },
      nullptr);
  png_set_IHDR(png, info, w_, h_, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < h_; ++y) png_write_row(png, const_cast<png_bytep>(rgb_.data() + 3 * y * w_));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  write_file_atomic(path, buffer);
}

void heap_picture(const std::filesystem::path& path, const Spheres& spheres, const HeapAngle& h,
                  double plate_z) {
  const int W = 900, H = 450;
  Canvas cv(W, H);
  // Extent: the heap's base radius with margin, in the first view's frame.
  const double half = std::max(1.3 * h.base_radius, 1.5 * h.height);
  const int bins = W - 80;
  const double u0 = -half, u1 = half;
  const auto prof = silhouette_profile(spheres, h.axis, h.views.empty() ? 0.0 : h.views[0].azimuth,
                                       u0, u1, bins, plate_z);
  const double zmax = 1.25 * h.height;
  const double sx = double(bins) / (u1 - u0);
  const double sz = std::min(sx, (H - 90.0) / zmax);  // same scale on both axes when possible
  const int ox = 40, oy = H - 50;
  auto X = [&](double u) { return ox + (u - u0) * sx; };
  auto Y = [&](double z) { return oy - (z - plate_z) * sz; };
  // Fit window band.
  cv.fill_rect(ox, int(Y(h.window_high * h.height)), ox + bins, int(Y(h.window_low * h.height)),
               0xeef4ff);
  for (int b = 0; b < bins; ++b)
    if (prof[b] > plate_z) cv.fill_rect(ox + b, int(Y(prof[b])), ox + b + 1, oy, 0x8a8a8a);
  cv.line(ox, oy, ox + bins, oy, 0x000000, 2);
  if (!h.views.empty()) {
    const auto& v = h.views[0];
    for (const auto* f : {&v.left, &v.right}) {
      if (f->points < 3) continue;
      const double sign = f == &v.left ? -1.0 : 1.0;
      // u = sign (a − slope z): the line from the plate to the apex height.
      const double za = plate_z, zb = plate_z + h.height;
      cv.line(X(sign * (f->intercept - f->slope * 0.0)), Y(za),
              X(sign * (f->intercept - f->slope * (zb - plate_z))), Y(zb), 0xd01010, 3);
      for (const auto& e : f->edge)
        cv.fill_rect(int(X(e.x())) - 1, int(Y(e.y())) - 1, int(X(e.x())) + 2, int(Y(e.y())) + 2,
                     0x1040d0);
    }
    const double deg = 180.0 / std::numbers::pi;
    cv.text(ox, 12,
            fmt::format("VIEW 0: L {:.1f} R {:.1f} DEG", v.left.angle * deg, v.right.angle * deg),
            0x000000, 2);
    cv.text(ox, 34,
            fmt::format("MEAN OF {} VIEWS: {:.1f} DEG (L {:.1f} R {:.1f})", h.views.size(),
                        h.angle * deg, h.angle_left * deg, h.angle_right * deg),
            0xd01010, 2);
    cv.text(ox, H - 30,
            fmt::format("FIT WINDOW {:.0f}-{:.0f}% OF H = {:.1f} MM", 100 * h.window_low,
                        100 * h.window_high, h.height * 1e3),
            0x303030, 2);
  }
  cv.save_png(path);
}

void curve_picture(const std::filesystem::path& path, const std::vector<Curve>& curves,
                   const std::string& x_label, const std::string& y_label) {
  const int W = 800, H = 500, ox = 90, oy = H - 60, pw = W - 130, ph = H - 110;
  Canvas cv(W, H);
  double tmax = 1e-9, mmax = 1e-9;
  for (const auto& c : curves)
    for (size_t i = 0; i < c.t.size(); ++i)
      tmax = std::max(tmax, c.t[i]), mmax = std::max(mmax, c.m[i]);
  mmax *= 1.1;
  auto X = [&](double t) { return ox + t / tmax * pw; };
  auto Y = [&](double m) { return oy - m / mmax * ph; };
  cv.line(ox, oy, ox + pw, oy, 0x000000, 2);
  cv.line(ox, oy, ox, oy - ph, 0x000000, 2);
  for (int k = 0; k <= 4; ++k) {
    const double t = tmax * k / 4, m = mmax * k / 4;
    cv.line(X(t), oy, X(t), oy + 6, 0x000000);
    cv.text(int(X(t)) - 15, oy + 12, fmt::format("{:.2g}", t), 0x000000, 2);
    cv.line(ox - 6, Y(m), ox, Y(m), 0x000000);
    cv.text(4, int(Y(m)) - 7, fmt::format("{:.2g}", m), 0x000000, 2);
  }
  cv.text(ox + pw / 2 - 20, H - 24, x_label, 0x000000, 2);
  cv.text(ox, 12, y_label, 0x000000, 2);
  const std::uint32_t colours[] = {0xd01010, 0x1040d0, 0x10a040, 0xa000a0, 0xd08000};
  int k = 0;
  for (const auto& c : curves) {
    const std::uint32_t col = colours[k % 5];
    for (size_t i = 1; i < c.t.size(); ++i)
      cv.line(X(c.t[i - 1]), Y(c.m[i - 1]), X(c.t[i]), Y(c.m[i]), col, 3);
    cv.text(ox + 20, 40 + 20 * k, c.label, col, 2);
    ++k;
  }
  cv.save_png(path);
}

}  // namespace clumpkit::rigs
