// The linear algebra of implicit damping (lib/src/dem/implicit_solve.hpp) against its
// definition: C assembled contact by contact in closed form equals the dense sum of
// c_n j_n j_nᵀ + c_t (j_t1 j_t1ᵀ + j_t2 j_t2ᵀ) over an orthonormal frame (n, t1, t2) at each
// contact point (j_e = (e, r × e)), and the inline LDLᵀ solve of (M + w dt C) y = F agrees with
// Eigen's LLT. Seeded random contacts, clump-like scales (mass 0.2 g, inertia 1e-9 kg m²).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cstdio>
#include <random>

#include "dem/implicit_solve.hpp"

namespace clumpkit::dem {
namespace {

Vector6d jac(const Eigen::Vector3d& r, const Eigen::Vector3d& e) {
  Vector6d j;
  j.head<3>() = e;
  j.tail<3>() = r.cross(e);
  return j;
}

TEST(ImplicitSolve, DampingMatrixAndSolveMatchTheirDefinitions) {
  std::mt19937_64 rng(20261123);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst_c = 0.0, worst_y = 0.0;
  for (int trial = 0; trial < 2000; ++trial) {
    Matrix6d c = Matrix6d::Zero(), dense = Matrix6d::Zero();
    const int contacts = 1 + trial % 12;
    for (int k = 0; k < contacts; ++k) {
      const Eigen::Vector3d r = 3e-3 * Eigen::Vector3d(g(rng), g(rng), g(rng));
      const Eigen::Vector3d n = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
      // c_t above, below and equal to c_n, and zero (a contact without tangential damping).
      const double cn = 0.5 * u(rng);
      const double ct = k % 4 == 3 ? 0.0 : (k % 4 == 2 ? cn : 0.8 * u(rng));
      add_dashpots(c, r, n, cn, ct);
      const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
      dense += cn * jac(r, n) * jac(r, n).transpose() +
               ct * (jac(r, t1) * jac(r, t1).transpose() + jac(r, t2) * jac(r, t2).transpose());
    }
    const Matrix6d full = c.selfadjointView<Eigen::Lower>();
    worst_c = std::max(worst_c, (full - dense).norm() / dense.norm());

    const double m = 2e-4, dt = 7e-6, w = 1.0 + u(rng);
    Eigen::Matrix3d inertia = Eigen::Vector3d(1e-9, 1.2e-9, 1.5e-9).asDiagonal();
    Matrix6d a = (w * dt) * c;
    a.diagonal().head<3>().array() += m;
    a.bottomRightCorner<3, 3>() += inertia;
    const Matrix6d a_full = a.selfadjointView<Eigen::Lower>();
    Vector6d f;
    for (int i = 0; i < 6; ++i) f[i] = i < 3 ? 1e-3 * g(rng) : 1e-6 * g(rng);
    const Vector6d expected = a_full.llt().solve(f);
    Matrix6d scratch = a;
    const Vector6d y = solve_spd(scratch, f);
    worst_y = std::max(worst_y, (y - expected).norm() / expected.norm());
  }
  std::printf("worst relative difference: C %.2e, solution %.2e\n", worst_c, worst_y);
  EXPECT_LT(worst_c, 1e-12);
  EXPECT_LT(worst_y, 1e-10);
}

}  // namespace
}  // namespace clumpkit::dem
