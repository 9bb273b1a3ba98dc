#include "clumpkit/fill/paper_rule.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "clumpkit/core/error.hpp"
#include "clumpkit/fill/paper_fill.hpp"
#include "clumpkit/geometry/shape_spec.hpp"

using namespace clumpkit;

namespace {
constexpr double kD = 6.0e-3;
const std::map<char, double> kH = {{'A', 5.4e-3}, {'B', 5.8e-3}, {'C', 6.2e-3}};
constexpr double kTol = 1e-12;

double lateral_gap(const Sphere& s, double d) {  // distance from sphere to lateral surface
  return 0.5 * d - (std::hypot(s.center.x(), s.center.y()) + s.radius);
}
double end_gap(const Sphere& s, double h) {  // distance from sphere to the nearer end face
  return 0.5 * h - (std::abs(s.center.z()) + s.radius);
}
}  // namespace

// SPEC §3, row by row: counts, radii, positions.
TEST(PaperRule, NineModelsHaveTheSpecsSpheres) {
  for (const PaperModel& m : paper_models()) {
    const double h = kH.at(m.pill);
    const Spheres s = paper_fill(kD, h, paper_preset(regime(kD, h), m.spheres));
    ASSERT_EQ(static_cast<int>(s.size()), m.spheres) << m.pill << m.spheres;
    std::multiset<double> zs;
    for (const Sphere& sp : s) zs.insert(std::round(sp.center.z() * 1e9) / 1e9);
    const double r = s.front().radius;
    for (const Sphere& sp : s) EXPECT_EQ(sp.radius, r);
    if (m.spheres == 4) {
      EXPECT_NEAR(r, h / 2, kTol);
      for (const Sphere& sp : s) {
        EXPECT_NEAR(std::hypot(sp.center.x(), sp.center.y()), kD / 2 - h / 2, kTol);
        EXPECT_NEAR(sp.center.z(), 0.0, kTol);
      }
      // 90° apart, first on +x.
      EXPECT_NEAR(s[0].center.y(), 0.0, kTol);
      EXPECT_NEAR(s[1].center.x(), 0.0, kTol);
    } else if (m.spheres == 12) {
      EXPECT_NEAR(r, h / 3, kTol);
      int up = 0;
      for (const Sphere& sp : s) {
        EXPECT_NEAR(std::hypot(sp.center.x(), sp.center.y()), kD / 2 - h / 3, kTol);
        EXPECT_NEAR(std::abs(sp.center.z()), h / 6, kTol);
        up += sp.center.z() > 0;
      }
      EXPECT_EQ(up, 6);
    } else if (m.spheres == 20) {
      EXPECT_NEAR(r, h / 4, kTol);
      int axial = 0, mid = 0;
      for (const Sphere& sp : s) {
        const double rho = std::hypot(sp.center.x(), sp.center.y());
        if (rho < kTol) {
          ++axial;
          EXPECT_NEAR(std::abs(sp.center.z()), h / 4, kTol);
        } else {
          EXPECT_NEAR(rho, kD / 2 - h / 4, kTol);
          if (std::abs(sp.center.z()) < kTol) {
            ++mid;
          } else {
            EXPECT_NEAR(std::abs(sp.center.z()), h / 4, kTol);
          }
        }
      }
      EXPECT_EQ(axial, 2);
      EXPECT_EQ(mid, 6);
    } else if (m.spheres == 2) {
      EXPECT_NEAR(r, kD / 2, kTol);
      for (const Sphere& sp : s) {
        EXPECT_NEAR(sp.center.head<2>().norm(), 0.0, kTol);
        EXPECT_NEAR(std::abs(sp.center.z()), h / 2 - kD / 2, kTol);
      }
    } else if (m.spheres == 18) {
      EXPECT_NEAR(r, h / 4, kTol);
      int mid = 0;
      for (const Sphere& sp : s) {
        EXPECT_NEAR(std::hypot(sp.center.x(), sp.center.y()), kD / 2 - h / 4, kTol);
        mid += std::abs(sp.center.z()) < kTol;
      }
      EXPECT_EQ(mid, 6);
    }
  }
}

// Every ring sphere touches the lateral surface; every outer-layer sphere touches an end face;
// nothing leaves the cylinder.
TEST(PaperRule, TangencyAndContainment) {
  for (const PaperModel& m : paper_models()) {
    const double h = kH.at(m.pill);
    const Spheres s = paper_fill(kD, h, paper_preset(regime(kD, h), m.spheres));
    double zmax = 0;
    for (const Sphere& sp : s) zmax = std::max(zmax, std::abs(sp.center.z()));
    for (const Sphere& sp : s) {
      EXPECT_GE(lateral_gap(sp, kD), -kTol);
      EXPECT_GE(end_gap(sp, h), -kTol);
      // Ring spheres, and the pill-wide spheres of the 2-sphere model, touch the lateral surface.
      const bool axial = sp.center.head<2>().norm() < kTol;
      if (!axial || m.spheres == 2) {
        EXPECT_NEAR(lateral_gap(sp, kD), 0.0, kTol) << m.pill << m.spheres;
      }
      if (std::abs(std::abs(sp.center.z()) - zmax) < kTol) {
        EXPECT_NEAR(end_gap(sp, h), 0.0, kTol) << m.pill << m.spheres;
      }
    }
  }
}

// Seeded property test over random cylinders and rules: a rule either fits inside or is
// rejected with a clear InputError; never a sphere outside.
TEST(PaperRule, RandomRulesFitOrAreRejected) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> ud(1e-3, 20e-3);
  int ok = 0, rejected = 0;
  for (int t = 0; t < 2000; ++t) {
    PaperRule r;
    r.layers = 1 + static_cast<int>(rng() % 5);
    r.per_ring = static_cast<int>(rng() % 10);
    r.axial = static_cast<PaperRule::Axial>(rng() % 3);
    r.radius_rule = static_cast<PaperRule::Radius>(rng() % 2);
    const double d = ud(rng), h = ud(rng);
    try {
      const Spheres s = paper_fill(d, h, r);
      EXPECT_EQ(static_cast<int>(s.size()), sphere_count(r));
      for (const Sphere& sp : s) {
        EXPECT_GE(lateral_gap(sp, d), -1e-12 * d);
        EXPECT_GE(end_gap(sp, h), -1e-12 * h);
      }
      ++ok;
    } catch (const InputError& e) {
      EXPECT_FALSE(e.field().empty());
      ++rejected;
    }
  }
  EXPECT_GT(ok, 100);
  EXPECT_GT(rejected, 100);
}

TEST(PaperRule, RejectsWithClearMessages) {
  EXPECT_THROW(paper_preset(CylinderRegime::Flat, 7), InputError);
  EXPECT_THROW(paper_preset(CylinderRegime::Tall, 4), InputError);
  // Diameter-sized spheres in a flat pill would leave through the end faces.
  EXPECT_THROW(paper_fill(6e-3, 5.4e-3, {2, 0, PaperRule::Axial::All, PaperRule::Radius::Diameter}),
               InputError);
  EXPECT_THROW(paper_fill(-6e-3, 5.4e-3, paper_preset(CylinderRegime::Flat, 12)), InputError);
  EXPECT_THROW(paper_fill(6e-3, 0.0, paper_preset(CylinderRegime::Flat, 12)), InputError);
  // A ring of spheres as wide as the pill collapses onto the axis.
  EXPECT_THROW(paper_fill(6e-3, 12e-3, {1, 6, PaperRule::Axial::None, PaperRule::Radius::Diameter}),
               InputError);
  try {
    paper_preset(CylinderRegime::Flat, 7);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("available: 4 12 20"), std::string::npos) << e.what();
  }
}

// The union's mass properties (ray sampling) agree with an independent Monte Carlo integration to
// 0.5 % for all nine models.
TEST(PaperFill, UnionMassPropertiesAgreeWithMonteCarlo) {
  for (const PaperModel& m : paper_models()) {
    const ShapeSpec shape = cylinder_shape(std::string("pill_") + m.pill, kD, kH.at(m.pill), 1380);
    PaperFillRequest req;
    req.spheres = m.spheres;
    const ClumpTemplate t = paper_fill_template(shape, req);
    // Independent: uniform random points in the bounding box, in the template frame.
    const Eigen::AlignedBox3d box = bounds(t.spheres);
    std::mt19937_64 rng(1234 + m.spheres);
    const auto u = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };  // [0, 1)
    const int n = 2'000'000;
    // Plain scalars (and 53 random bits, not std::generate_canonical's log per draw) in a loop of
    // 18 M points: in the sanitizer build's -O1, Eigen's small-matrix expressions made it slow.
    struct Ball {
      double x, y, z, r2;
    };
    std::vector<Ball> balls;
    for (const Sphere& s : t.spheres)
      balls.push_back({s.center.x(), s.center.y(), s.center.z(), s.radius * s.radius});
    const double lo[3] = {box.min().x(), box.min().y(), box.min().z()};
    const double span[3] = {box.sizes().x(), box.sizes().y(), box.sizes().z()};
    long inside = 0;
    double m1[3] = {0, 0, 0}, m2[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (int i = 0; i < n; ++i) {
      double p[3];
      for (int k = 0; k < 3; ++k) p[k] = lo[k] + u() * span[k];
      for (const Ball& b : balls) {
        const double dx = p[0] - b.x, dy = p[1] - b.y, dz = p[2] - b.z;
        if (dx * dx + dy * dy + dz * dz < b.r2) {
          ++inside;
          for (int a = 0; a < 3; ++a) {
            m1[a] += p[a];
            for (int c = 0; c < 3; ++c) m2[a][c] += p[a] * p[c];
          }
          break;
        }
      }
    }
    const double vbox = box.volume();
    const double vol = vbox * inside / n;
    EXPECT_NEAR(t.mass.volume / vol, 1.0, 5e-3) << m.pill << m.spheres;
    const Eigen::Vector3d com = Eigen::Vector3d(m1[0], m1[1], m1[2]) / inside;
    const Eigen::Matrix3d second =
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(&m2[0][0]);
    const Eigen::Matrix3d s2 = (second / inside - com * com.transpose()) * vol * 1380.0;
    const Eigen::Matrix3d inertia = s2.trace() * Eigen::Matrix3d::Identity() - s2;
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(t.mass.inertia_tensor(k, k) / inertia(k, k), 1.0, 5e-3) << m.pill << m.spheres;
    EXPECT_LT(com.norm(), 2e-3 * kD);
    // The union is lighter than the sum of the spheres (overlaps are counted once).
    double sum = 0;
    for (const Sphere& s : t.spheres) sum += 4.0 / 3.0 * M_PI * std::pow(s.radius, 3);
    if (t.spheres.size() > 1) {
      EXPECT_LT(t.mass.volume, 0.95 * sum);
    }
  }
}
