// The HTML report in a real headless browser (Debian's chromium): the page a diagnosis writes is
// loaded offline, its DOM after rendering holds the tables, plots and verdict, and a screenshot
// of it is not blank. Skipped when chromium is not installed (CI installs it).
#include <gtest/gtest.h>
#include <png.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <string>

#include "clumpkit/calibrate/diagnosis.hpp"
#include "clumpkit/calibrate/report.hpp"
#include "fake_simulator.hpp"

using namespace clumpkit;
using namespace clumpkit::calibrate;

namespace {

namespace fs = std::filesystem;
const fs::path kWork = fs::path(CLUMPKIT_BINARY_DIR) / "tests" / "calibrate" / "report_browser";

std::string find_browser() {
  for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome"})
    if (fs::exists(p)) return p;
  return "";
}

std::string text(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

int count(const std::string& s, const std::string& what) {
  int n = 0;
  for (size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

// A diagnosis with a failing baseline, on the analytic stand-in for the rigs (the report, not
// the physics, is under test here), written with a chain of two model versions.
void write_diagnosis_report(const fs::path& dir) {
  fake::FakeSimulator sim;
  ParticleModel base =
      load_model(CLUMPKIT_SOURCE_DIR "/shapes/models/paper_A12.toml", CLUMPKIT_SOURCE_DIR);
  set_model_effect(base, "effects.rolling_friction", "off", "test");
  ParticleModel truth = base;
  set_model_effect(truth, "effects.rolling_friction", "0.15", "test");
  auto ms = parse_measurements(
      "rig,sample,setting,quantity,value,std,n,unit\n"
      "bulk_density,A,wall=organic_glass,bulk_density,1,1,3,kg/m^3\n"
      "angle_of_repose,A,plate=galvanized_steel,angle,1,1,3,deg\n"
      "angle_of_repose,A,plate=abs_plastic,angle,1,1,3,deg\n"
      "discharge,A,rpm=15,pocket_mass,1,1,3,kg\n",
      "template.csv");
  const auto sims = simulate_measurements(sim, truth, ms, "mini", 3, 99);
  for (auto& m : ms) {
    m.value = sims.at(m.key()).mean;
    m.std = 0.03 * m.value;
  }
  DiagnoseOptions o;
  o.suggest = false;
  const Diagnosis d = diagnose(base, ms, sim, o);
  ReportInput rep;
  rep.title = "clumpkit diagnose: browser check";
  rep.chain.emplace_back("baseline", d.baseline);
  rep.chain.emplace_back("baseline+" + d.candidates.front().candidate.effect,
                         d.candidates.front().comparison);
  rep.diagnosis = &d;
  write_report(rep, dir);
}

// Fraction of pixels of a PNG screenshot that are not (near) white.
double inked_fraction(const fs::path& png_file) {
  FILE* f = std::fopen(png_file.c_str(), "rb");
  if (!f) return -1;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(f);
    return -1;
  }
  png_init_io(png, f);
  png_read_info(png, info);
  png_set_expand(png);
  png_set_strip_16(png);
  png_set_strip_alpha(png);
  png_set_gray_to_rgb(png);
  png_read_update_info(png, info);
  const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  const size_t stride = png_get_rowbytes(png, info);
  std::vector<unsigned char> pixels(stride * h);
  std::vector<png_bytep> rows(h);
  for (png_uint_32 y = 0; y < h; ++y) rows[y] = pixels.data() + y * stride;
  png_read_image(png, rows.data());
  png_destroy_read_struct(&png, &info, nullptr);
  std::fclose(f);
  long inked = 0;
  for (png_uint_32 y = 0; y < h; ++y)
    for (png_uint_32 x = 0; x < w; ++x) {
      const unsigned char* p = rows[y] + 3 * x;
      if (p[0] < 230 || p[1] < 230 || p[2] < 230) ++inked;
    }
  return double(inked) / (double(w) * double(h));
}

TEST(ReportInBrowser, RendersOfflineWithTablesPlotsAndVerdict) {
  const std::string browser = find_browser();
  if (browser.empty()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium)";
  fs::remove_all(kWork);
  fs::create_directories(kWork);
  write_diagnosis_report(kWork / "report");
  const fs::path page = kWork / "report" / "index.html";
  ASSERT_TRUE(fs::exists(page));
  // Offline: nothing in the page points at the network.
  const std::string html = text(page);
  EXPECT_FALSE(std::regex_search(html, std::regex(R"((src|href)\s*=\s*"https?:)")));

  // The DOM after the browser has parsed and laid it out.
  const std::string flags =
      " --headless --no-sandbox --disable-gpu --no-first-run "
      "--disable-extensions --user-data-dir=" +
      (kWork / "profile").string();
  const fs::path dom = kWork / "dom.html", shot = kWork / "shot.png";
  const std::string url = "file://" + fs::absolute(page).string();
  int rc = std::system((browser + flags + " --dump-dom " + url + " > " + dom.string() + " 2> " +
                        (kWork / "dump.err").string())
                           .c_str());
  ASSERT_EQ(rc, 0) << text(kWork / "dump.err");
  const std::string d = text(dom);
  EXPECT_NE(d.find("id=\"observables\""), std::string::npos);
  EXPECT_NE(d.find("id=\"candidates\""), std::string::npos);
  EXPECT_NE(d.find("id=\"verdict\""), std::string::npos);
  EXPECT_NE(d.find("rolling_friction"), std::string::npos);
  EXPECT_GE(count(d, "<svg"), 3) << "plots: simulated vs measured, residual pattern, chain";
  EXPECT_GE(count(d, "<tr"), 1 + 4 + 1);  // header + 4 observables + candidates
  EXPECT_GE(count(d, "<circle"), 4);      // one marker per observable at least

  // A screenshot: the page is drawn (not blank).
  rc = std::system((browser + flags + " --window-size=1200,1600 --screenshot=" + shot.string() +
                    " " + url + " > " + (kWork / "shot.err").string() + " 2>&1")
                       .c_str());
  ASSERT_EQ(rc, 0) << text(kWork / "shot.err");
  ASSERT_TRUE(fs::exists(shot)) << text(kWork / "shot.err");
  const double ink = inked_fraction(shot);
  EXPECT_GT(ink, 0.01) << "the screenshot is (nearly) blank";
  EXPECT_LT(ink, 0.9) << "the screenshot is (nearly) all dark";
}

}  // namespace
