#pragma once
// The linear algebra of implicit damping (docs/dem.md): a clump's 6×6 damping matrix C in world
// coordinates (v, ω), assembled contact by contact, and the solve of (M + w dt C) y = F.
// Internal to the DEM module (step.cpp); tested against a dense assembly and Eigen's LLT in
// tests/dem/implicit_solve_test.cpp.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>

namespace clumpkit::dem {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// Adds a contact's dashpots to a clump's damping matrix C in world coordinates (v, ω), lower
// triangle: c_t on every direction of the contact point's velocity v + ω × r, and c_n − c_t
// more along the normal. For the isotropic part, Σ_e j_e j_eᵀ over the axes e with
// j_e = (e, r × e) is [[I, −[r]ₓ], [[r]ₓ, |r|² I − r rᵀ]] in closed form.
inline void add_dashpots(Matrix6d& c, const Eigen::Vector3d& r, const Eigen::Vector3d& n, double cn,
                         double ct) {
  if (ct > 0.0) {
    const double r2 = r.squaredNorm();
    for (int i = 0; i < 3; ++i) {
      c(i, i) += ct;
      for (int k = 0; k <= i; ++k) c(3 + i, 3 + k) += ct * ((i == k ? r2 : 0.0) - r[i] * r[k]);
    }
    // Lower-left block (rows ω, columns v): [r]ₓ.
    c(3, 1) -= ct * r.z(), c(3, 2) += ct * r.y();
    c(4, 0) += ct * r.z(), c(4, 2) -= ct * r.x();
    c(5, 0) -= ct * r.y(), c(5, 1) += ct * r.x();
  }
  const double k = cn - ct;
  if (k != 0.0) {
    Vector6d j;
    j.head<3>() = n;
    j.tail<3>() = r.cross(n);
    // Rank-one update k j jᵀ of the lower triangle, written out (Eigen's selfadjoint rank
    // update is a generic routine that cost more than the rest of the assembly).
    for (int col = 0; col < 6; ++col) {
      const double kj = k * j[col];
      for (int row = col; row < 6; ++row) c(row, col) += kj * j[row];
    }
  }
}

// Solves A y = f for a symmetric positive definite A given by its lower triangle, by LDLᵀ
// (unit lower L overwriting the strict lower triangle), fixed size and inline: the solve of
// every implicitly damped clump and step. Six reciprocals and no square root: a Cholesky's
// chain of square roots and divisions cost as much as assembling the matrix.
inline Vector6d solve_spd(Matrix6d& a, const Vector6d& f) {
  std::array<double, 6> dd, inv_d;
  for (int col = 0; col < 6; ++col) {
    // Row col of L D (entries k < col) into the column's scratch: a(col, k) · d_k.
    std::array<double, 6> ld;
    double d = a(col, col);
    for (int k = 0; k < col; ++k) {
      ld[k] = a(col, k) * dd[k];
      d -= a(col, k) * ld[k];
    }
    dd[col] = d;
    inv_d[col] = 1.0 / d;
    for (int row = col + 1; row < 6; ++row) {
      double v = a(row, col);
      for (int k = 0; k < col; ++k) v -= a(row, k) * ld[k];
      a(row, col) = v * inv_d[col];
    }
  }
  Vector6d y = f;
  for (int i = 1; i < 6; ++i)
    for (int k = 0; k < i; ++k) y[i] -= a(i, k) * y[k];
  for (int i = 0; i < 6; ++i) y[i] *= inv_d[i];
  for (int i = 4; i >= 0; --i)
    for (int k = i + 1; k < 6; ++k) y[i] -= a(k, i) * y[k];
  return y;
}

}  // namespace clumpkit::dem
