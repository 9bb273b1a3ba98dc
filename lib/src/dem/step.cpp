// World::step and its stages. Integration is velocity Verlet for translation and, for rotation,
// the symmetric splitting of the free rigid body into rotations about the principal axes
// (Dullweber, Leimkuhler & McLachlan 1997), which keeps the gyroscopic term exact per sub-step.
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "clumpkit/core/error.hpp"
#include "dem/implicit_solve.hpp"
#include "dem/world_impl.hpp"

namespace clumpkit::dem {

namespace {

double seconds_since(Clock::time_point& t0) {
  const auto t1 = Clock::now();
  const double s = std::chrono::duration<double>(t1 - t0).count();
  t0 = t1;
  return s;
}

// Body angular momentum π rotated by −θ about principal axis k (the body turns by +θ), given
// c = cos θ and s = sin θ.
void rotate_momentum(Eigen::Vector3d& pi, int k, double c, double s) {
  const int a = (k + 1) % 3, b = (k + 2) % 3;
  const double pa = pi[a], pb = pi[b];
  pi[a] = c * pa + s * pb;
  pi[b] = -s * pa + c * pb;
}

// sin x and cos x. A step turns a clump by a small angle (|x| < 0.01 rad is typical: ω dt / 2
// with ω ~ 100 rad/s and dt ~ 1e-5 s), where the Taylor series to x^9 / x^10 is exact to the
// last bit (the next terms are below 1e-20 relative) and costs a fraction of a libm sincos,
// which this stage called five times per clump and step.
inline void half_angle_sincos(double x, double& s, double& c) {
  if (std::abs(x) < 1e-3) {
    // The usual case (ω dt / 4 ~ 1e-4): the terms after x^5 / x^4 are below 1e-20 relative.
    const double x2 = x * x;
    s = x * (1.0 - x2 * (1.0 / 6) * (1.0 - x2 * (1.0 / 20)));
    c = 1.0 - x2 * 0.5 * (1.0 - x2 * (1.0 / 12));
    return;
  }
  if (std::abs(x) < 0.01) {
    const double x2 = x * x;
    s = x * (1.0 - x2 * (1.0 / 6) *
                       (1.0 - x2 * (1.0 / 20) * (1.0 - x2 * (1.0 / 42) * (1.0 - x2 * (1.0 / 72)))));
    c = 1.0 -
        x2 * 0.5 *
            (1.0 - x2 * (1.0 / 12) *
                       (1.0 - x2 * (1.0 / 30) * (1.0 - x2 * (1.0 / 56) * (1.0 - x2 * (1.0 / 90)))));
    return;
  }
  s = std::sin(x);
  c = std::cos(x);
}

// Implicit damping (docs/dem.md): bounds on the rates at which one contact's dashpots act on
// one clump, 1/s, normal and tangential apart (the engine integrates them differently). The
// dashpots (linear coefficients c_n, c_t on the relative velocity) act at the contact point,
// whose mobility (inverse effective mass) along the normal is at most 1/m + |r × n|² / I_min and
// along any direction at most 1/m + |r|² / I_min, r from the clump's centre of mass. Summed over
// a clump's contacts (pair contacts twice: (x + y)ᵀ C (x + y) ≤ 2 (xᵀ C x + yᵀ C y)), times the
// step, they bound the fastest damped modes the clump takes part in.
inline Eigen::Vector2d dashpot_load(const ContactForce& f, const TypeData& t,
                                    const Eigen::Vector3d& r, const Eigen::Vector3d& n) {
  const double inv_i = t.inv_inertia.maxCoeff();
  return {f.dashpot_n * (t.inv_mass + r.cross(n).squaredNorm() * inv_i),
          f.dashpot_t * (t.inv_mass + r.squaredNorm() * inv_i)};
}

// How the overlap check names a contact: two clumps, or a clump and a wall.
std::string clumps_what(int ci, int cj) {
  return "clumps " + std::to_string(ci) + " and " + std::to_string(cj);
}
std::string wall_what(int c, const std::string& wall) {
  return "clump " + std::to_string(c) + " and wall '" + wall + "'";
}

}  // namespace

void World::step() {
  Impl& w = *impl_;
  if (w.settings.threads <= 0)
    w.threads = static_cast<long>(w.s_r.size()) >= kAutoThreadsMin ? w.max_threads : 1;
  w.ensure_forces();
  auto t0 = Clock::now();
  w.kick_and_drift();
  w.time += w.dt;
  ++w.steps;
  w.profile.integrate += seconds_since(t0);
  w.move_walls();
  w.profile.walls += seconds_since(t0);
  w.run_factories();
  w.profile.insert += seconds_since(t0);
  w.update_neighbours();
  w.profile.neighbours += seconds_since(t0);
  w.detect_contacts();
  w.profile.contacts += seconds_since(t0);
  w.compute_forces(w.dt);
  w.profile.forces += seconds_since(t0);
  w.kick();
  w.profile.integrate += seconds_since(t0);
  if (w.settings.pinch_release > 0.0) w.release_pinched(*this);
  w.check_health();
  w.profile.checks += seconds_since(t0);
  ++w.profile.steps;
}

void World::run_until(double t) {
  while (impl_->time < t - 1e-12 * impl_->dt) step();
}

void World::Impl::ensure_forces() {
  if (forces_valid) return;
  update_neighbours();
  detect_contacts();
  compute_forces(0.0);  // no history increment: the springs start at rest
  forces_valid = true;
  if (!check_initialised) {
    check_energy = kinetic_energy() + potential_energy() + elastic;
    check_ke = kinetic_energy();
    check_elastic = elastic;
    wall_work = inserted_energy = 0.0;
    check_initialised = true;
  }
}

void World::Impl::update_spheres(int first_clump) {
  const int n0 = first_clump < static_cast<int>(c_first.size()) ? c_first[first_clump]
                                                                : static_cast<int>(s_r.size());
  const int ns = static_cast<int>(s_r.size());
#pragma omp parallel for num_threads(threads) schedule(static) if (ns - n0 >= kParallelMin)
  for (int s = n0; s < ns; ++s) {
    const int c = s_clump[s];
    s_pos[s] = sphere_position(c_x[c], c_R[c], s_off[s]);
  }
}

// Half kick of momentum and angular momentum. Rolling resistance (standard model) is applied
// after the other torques and limited so that it can stop a rotation but never reverse it.
static inline void half_kick(World::Impl& w, int c, double h) {
  const TypeData& t = w.types[w.c_type[c]];
  w.c_v[c] += h * (t.inv_mass * w.c_f[c] + w.settings.gravity);
  Eigen::Vector3d pi = t.inertia.cwiseProduct(w.c_wb[c]);
  pi += h * (w.c_R[c].transpose() * w.c_t[c]);
  if (w.c_mroll[c] > 0.0) {
    // −M ω̂ with ω̂ the direction of rotation now, at most enough to stop the rotation.
    const Eigen::Vector3d w0 = pi.cwiseProduct(t.inv_inertia);
    const double wn = w0.norm();
    if (wn > 0.0) {
      const Eigen::Vector3d dir = w0 / wn;
      Eigen::Vector3d dpi = -(h * w.c_mroll[c]) * dir;
      const double along = -dpi.cwiseProduct(t.inv_inertia).dot(dir);
      if (along > wn) dpi *= wn / along;
      pi += dpi;
    }
  }
  w.c_wb[c] = pi.cwiseProduct(t.inv_inertia);
}

// One sub-step of the free rotation: the body turns by θ = τ π_K / I_K about principal axis K.
// The axis is a template argument so that the five sub-steps of a step are straight-line code
// with every index known (this chain of dependent operations is most of the drift's cost).
template <int K>
inline void free_rotation_substep(double tau, const TypeData& t, Eigen::Vector3d& pi, double& qw,
                                  Eigen::Vector3d& qv) {
  const double theta = tau * pi[K] * t.inv_inertia[K];
  if (theta == 0.0) return;
  // One sincos of θ/2 serves the quaternion and (by the double-angle formulas) the momentum
  // rotation.
  double sh, ch;
  half_angle_sincos(0.5 * theta, sh, ch);
  rotate_momentum(pi, K, 1.0 - 2.0 * sh * sh, 2.0 * sh * ch);
  // q ← q · (ch, sh e_K), written out: the factor has one vector component.
  constexpr int a = (K + 1) % 3, b = (K + 2) % 3;
  const double w0 = qw, vk = qv[K], va = qv[a], vb = qv[b];
  qw = w0 * ch - sh * vk;
  qv[K] = w0 * sh + ch * vk;
  qv[a] = ch * va + sh * vb;
  qv[b] = ch * vb - sh * va;
}

void World::Impl::kick_and_drift() {
  const int nc = static_cast<int>(c_x.size());
  const int ns = static_cast<int>(s_r.size());
  const double h = 0.5 * dt;
  TopTwo top;
  c_disp2.resize(nc);
  // Two loops over the clumps in one parallel region: the first kicks and turns each clump,
  // the second moves its spheres. Apart, the first loop's iterations are short enough for the
  // processor to overlap the dependent sincos chains of neighbouring clumps. Both loops share
  // the static schedule, so each thread moves the spheres of the clumps it turned (no barrier
  // between them). The clumps' largest displacements since the last neighbour rebuild come
  // along for free.
#pragma omp parallel num_threads(threads) if (ns >= kParallelMin)
  {
    TopTwo mine;
#pragma omp for schedule(static) nowait
    for (int c = 0; c < nc; ++c) {
      half_kick(*this, c, h);
      c_x[c] += dt * c_v[c];
      // Free rotation over dt: R1(h) R2(h) R3(dt) R2(h) R1(h) in the principal frame.
      const TypeData& t = types[c_type[c]];
      Eigen::Vector3d pi = t.inertia.cwiseProduct(c_wb[c]);
      double qw = c_q[c].w();
      Eigen::Vector3d qv = c_q[c].vec();
      free_rotation_substep<0>(h, t, pi, qw, qv);
      free_rotation_substep<1>(h, t, pi, qw, qv);
      free_rotation_substep<2>(dt, t, pi, qw, qv);
      free_rotation_substep<1>(h, t, pi, qw, qv);
      free_rotation_substep<0>(h, t, pi, qw, qv);
      Eigen::Quaterniond q(qw, qv.x(), qv.y(), qv.z());
      q.normalize();
      c_q[c] = q;
      c_R[c] = q.toRotationMatrix();
      c_wb[c] = pi.cwiseProduct(t.inv_inertia);
    }
#pragma omp for schedule(static) nowait
    for (int c = 0; c < nc; ++c) {
      // The clump's spheres (contiguous).
      const Eigen::Vector3d x = c_x[c];
      const Eigen::Matrix3d R = c_R[c];
      double dc = 0.0;
      const int s1 = sphere_end(c);
      for (int s = c_first[c]; s < s1; ++s) {
        const Eigen::Vector3d p = sphere_position(x, R, s_off[s]);
        s_pos[s] = p;
        dc = std::max(dc, (p - s_pos_build[s]).squaredNorm());
      }
      c_disp2[c] = dc;
      mine.add(dc);
    }
    // The two largest of a set do not depend on the order it is merged in.
#pragma omp critical(clumpkit_drift_top_two)
    {
      top.add(mine.first);
      top.add(mine.second);
    }
  }
  drift_disp2 = top;
  drift_disp_valid = true;
}

void World::Impl::kick() {
  const int nc = static_cast<int>(c_x.size());
  const double h = 0.5 * dt;
#pragma omp parallel for num_threads(threads) schedule(static) if (nc >= kParallelMin)
  for (int c = 0; c < nc; ++c) half_kick(*this, c, h);
}

void World::Impl::move_walls() {
  for (WallData& wd : walls) {
    const WallPose pose = wall_pose(wd.motion, time);
    wd.state.pose = pose;
    wd.state.torque_reference = wd.torque_reference0 + (pose.axis_point - pose.reference_point);
    wd.vertices.resize(wd.ref_vertices.size());
    for (size_t k = 0; k < wd.ref_vertices.size(); ++k)
      wd.vertices[k] = pose.apply(wd.ref_vertices[k]);
    // Normals turn with the wall (a translation leaves them as they are).
    const bool turned = !pose.rotation.isIdentity(0.0);
    if (wd.normals.size() != wd.ref_normals.size() || turned || wd.normals_turned) {
      wd.normals.resize(wd.ref_normals.size());
      for (size_t k = 0; k < wd.ref_normals.size(); ++k)
        wd.normals[k] = pose.rotation * wd.ref_normals[k];
      wd.normals_turned = turned;
    }
  }
}

void World::Impl::update_neighbours() {
  TopTwo top;
  if (drift_disp_valid) {
    top = drift_disp2;  // measured by kick_and_drift; spheres added since have not moved
  } else {
    const int nc = static_cast<int>(c_first.size());
    c_disp2.resize(nc);
    for (int c = 0; c < nc; ++c) {
      double dc = 0.0;
      for (int s = c_first[c]; s < sphere_end(c); ++s)
        dc = std::max(dc, (s_pos[s] - s_pos_build[s]).squaredNorm());
      c_disp2[c] = dc;
      top.add(dc);
    }
  }
  drift_disp_valid = false;
  // A listed pair (spheres of two clumps) stays complete while the two spheres' displacements
  // sum to less than the skin; the worst pair is the two clumps that moved most. (Twice the
  // largest displacement, the usual bound, rebuilt the whole list for one fast pill.)
  const double d1 = std::sqrt(top.first), d2 = std::sqrt(top.second);
  double dw = 0.0;
  for (const WallData& wd : walls)
    for (size_t k = 0; k < wd.vertices.size(); ++k)
      dw = std::max(dw, (wd.vertices[k] - wd.vertices_build[k]).squaredNorm());
  dw = std::sqrt(dw);
  // The displacement bound is a worst case: the two clumps that moved most may be far apart.
  // Where only it fires, the last rebuild's cells are searched for a touching pair the list
  // lacks; the list is rebuilt only if one is found. A pair touching or not, the contacts and
  // forces are the same (the list is a superset cache), so the trajectory keeps its bits.
  bool rebuild = need_rebuild || d1 + dw > skin;
  if (!rebuild && d1 + d2 > skin) {
    rebuild = !settings.neighbour_search || !pair_list_complete(d1);
    if (!rebuild) ++profile.neighbour_rebuilds_spared;
  }
  if (rebuild) {
    rebuild_neighbours();
    ++profile.neighbour_rebuilds;
  }
}

void World::Impl::detect_contacts() {
  // Sphere pairs. Each thread takes a contiguous block of the (i, j)-sorted list: first it
  // notes the pairs in contact (index and distance, 16 bytes each), then, at its block's
  // offset in the contact list, writes their geometry. The list is the same for any thread
  // count. Entries are overwritten in place (every field the stages read is assigned), not
  // re-constructed: zeroing ~200 bytes per contact every step cost more than the scan.
  const int np = static_cast<int>(pairs.size());
  const int nt = np >= kParallelMin ? std::max(threads, 1) : 1;
  if (pair_live.size() != pairs.size()) {
    pair_live.resize(np);
    for (int k = 0; k < np; ++k) pair_live[k] = history_empty(pair_hist[k]) ? 0 : 1;
  }
  scratch_touch.resize(nt);
  scratch_max.assign(nt, {0.0, -1});
  // Each thread's block of the contact list starts at offset[t]; compute_forces gives the
  // block's laws to the same thread.
  std::vector<int>& offset = contact_block_start;
  offset.assign(nt + 1, 0);
#pragma omp parallel num_threads(nt) if (nt > 1)
  {
    const int t = omp_get_thread_num();
    const int k0 = static_cast<int>(std::int64_t(np) * t / nt);
    const int k1 = static_cast<int>(std::int64_t(np) * (t + 1) / nt);
    std::vector<std::pair<int, double>>& touch = scratch_touch[t].v;
    touch.clear();
    for (int k = k0; k < k1; ++k) {
      const PairEntry& p = pairs[k];
      const double rr = s_r[p.i] + s_r[p.j];
      const double d2 = (s_pos[p.i] - s_pos[p.j]).squaredNorm();
      if (d2 < rr * rr) {
        touch.push_back({k, std::sqrt(d2)});
        pair_live[k] = 1;
      } else if (pair_live[k]) {
        // Most listed pairs are apart with an empty history, known from the flag alone (their
        // histories are not read: at paper scale that was a stream of ~2 MB per step).
        ContactHistory& h = pair_hist[k];
        if (h.damping != 0.0) {
          // Closing: the overlap ended during the step, one damping impulse is left (a
          // negative distance marks it).
          h.shear.setZero();
          h.roll.setZero();
          touch.push_back({k, -std::sqrt(d2)});
        } else {
          if (!h.shear.isZero(0.0) || !h.roll.isZero(0.0)) h = ContactHistory{};
          pair_live[k] = 0;
        }
      }
    }
    offset[t + 1] = static_cast<int>(touch.size());
#pragma omp barrier
#pragma omp single
    {
      for (int u = 0; u < nt; ++u) offset[u + 1] += offset[u];
      if (static_cast<int>(pair_contacts.size()) < offset[nt]) pair_contacts.resize(offset[nt]);
      pair_contact_clumps.resize(offset[nt]);
    }
    double best = 0.0;
    int best_k = -1;
    size_t o = offset[t];
    for (const auto& [k, sd] : touch) {
      const PairEntry& p = pairs[k];
      pair_contact_clumps[o] = {s_clump[p.i], s_clump[p.j]};
      PairContactData& pc = pair_contacts[o++];
      const double rr = s_r[p.i] + s_r[p.j];
      const double d = std::abs(sd);
      pc.pair = k;
      pc.closing = sd < 0.0;  // a closing pair is apart: its distance is > 0
      pc.overlap = rr - d;
      pc.normal =
          d > 0.0 ? Eigen::Vector3d((s_pos[p.i] - s_pos[p.j]) / d) : Eigen::Vector3d::UnitZ();
      pc.point = s_pos[p.i] - (s_r[p.i] - 0.5 * pc.overlap) * pc.normal;
      if (pc.closing) pc.overlap = 0.0;
      const double ratio = pc.overlap / std::min(s_r[p.i], s_r[p.j]);
      if (ratio > best) best = ratio, best_k = k;
    }
    scratch_max[t] = {best, best_k};
  }
  pair_contacts.resize(offset[nt]);
  max_overlap_ratio = 0.0;
  for (int t = 0; t < nt; ++t)
    if (scratch_max[t].first > max_overlap_ratio) {
      max_overlap_ratio = scratch_max[t].first;
      const PairEntry& p = pairs[scratch_max[t].second];
      max_overlap_what = clumps_what(s_clump[p.i], s_clump[p.j]);
    }

  // Sphere-wall contacts, one sphere at a time. Candidates closer than the radius are sorted
  // by distance; a candidate whose contact point lies on or behind the tangent plane of an
  // already accepted contact, or whose normal is within 10° of it, is the same contact seen
  // through another triangle of the same (nearly) flat region, a shared edge or a vertex, and
  // is dropped. A sphere therefore feels one contact per smooth region of a wall.
  if (wall_active_dirty) refresh_wall_active();
  const int na = static_cast<int>(wall_active.size());
  const double merge_cos = std::cos(10.0 * 3.14159265358979323846 / 180.0);
  std::vector<double>& ratio_s = scratch_ratio;
  std::vector<int>& overflow = scratch_overflow;
  ratio_s.assign(na, 0.0);
  overflow.assign(na, 0);
  // Statically shared out, as the wall laws are (compute_forces): each sphere's wall contacts
  // stay with one thread from step to step.
#pragma omp parallel for num_threads(threads) schedule(static) if (na >= 64)
  for (int a = 0; a < na; ++a) {
    const int s = wall_active[a];
    struct Cand {
      double dist;
      int wall, tri;
      Eigen::Vector3d point;
    };
    Cand cands[32];
    int nc = 0;
    const Eigen::Vector3d& p = s_pos[s];
    const double r = s_r[s];
    for (int k = wall_cand_start[s]; k < wall_cand_start[s + 1] && nc < 32; ++k) {
      const auto [wi, ti] = wall_cand[k];
      const WallData& wd = walls[wi];
      // Most candidates (within the skin, not touching) stop at this one dot product.
      if (beyond_plane(wd, ti, p, r)) continue;
      const auto& tri = wd.triangles[ti];
      const Eigen::Vector3d c = closest_point_on_triangle(p, wd.vertices[tri[0]],
                                                          wd.vertices[tri[1]], wd.vertices[tri[2]]);
      const double d = (p - c).norm();
      if (d < r) cands[nc++] = {d, wi, ti, c};
    }
    // The usual case: nothing touching and no contact held. A slot not held (wall −1) is all
    // zero (it is only ever written as such), so there is nothing to carry over or clear.
    if (nc == 0 && wall_held[s] == 0) {
      wall_contact_n[s] = 0;
      continue;
    }
    std::sort(cands, cands + nc, [](const Cand& x, const Cand& y) {
      if (x.dist != y.dist) return x.dist < y.dist;
      if (x.wall != y.wall) return x.wall < y.wall;
      return x.tri < y.tri;
    });
    auto& out = wall_contacts[a];
    int n = 0;
    for (int k = 0; k < nc; ++k) {
      const Cand& cd = cands[k];
      Eigen::Vector3d normal;
      if (cd.dist > 0.0) {
        normal = (p - cd.point) / cd.dist;
      } else {  // centre exactly on the triangle: use the face normal
        const WallData& wd = walls[cd.wall];
        const auto& tri = wd.triangles[cd.tri];
        normal = (wd.vertices[tri[1]] - wd.vertices[tri[0]])
                     .cross(wd.vertices[tri[2]] - wd.vertices[tri[0]])
                     .normalized();
      }
      bool same = false;
      for (int j = 0; j < n && !same; ++j)
        same = (cd.point - out[j].point).dot(out[j].normal) <= 1e-9 * r ||
               normal.dot(out[j].normal) >= merge_cos;
      if (same) continue;
      if (n == kWallSlots) {
        overflow[a] = 1;
        break;
      }
      WallContactData& wc = out[n++];
      wc.wall = cd.wall;
      wc.normal = normal;
      wc.point = cd.point;
      wc.overlap = r - cd.dist;
      ratio_s[a] = std::max(ratio_s[a], wc.overlap / r);
    }
    // Carry the history springs over: same wall, closest normal.
    auto& slots = wall_slots[s];
    if (n == 1 && wall_held[s] == 1 && slots[0].wall == out[0].wall &&
        slots[0].normal.dot(out[0].normal) > 0.5) {
      // The usual case, one contact that goes on: what the general case below gives, in place.
      slots[0].normal = out[0].normal;
      out[0].closing = false;
      wall_contact_n[s] = 1;
      continue;
    }
    std::array<WallSlot, kWallSlots> next{};
    std::array<bool, kWallSlots> used{};
    for (int k = 0; k < n; ++k) {
      int best = -1;
      double best_dot = 0.5;
      for (int j = 0; j < kWallSlots; ++j)
        if (!used[j] && slots[j].wall == out[k].wall) {
          const double dd = slots[j].normal.dot(out[k].normal);
          if (dd > best_dot) best_dot = dd, best = j;
        }
      next[k].wall = out[k].wall;
      next[k].normal = out[k].normal;
      if (best >= 0) {
        used[best] = true;
        next[k].history = slots[best].history;
      }
      out[k].closing = false;
    }
    // Contacts that ended during the step and still owe their last damping impulse.
    for (int j = 0; j < kWallSlots && n < kWallSlots; ++j)
      if (!used[j] && slots[j].wall >= 0 && slots[j].history.damping != 0.0) {
        WallContactData& wc = out[n];
        wc.wall = slots[j].wall;
        wc.normal = slots[j].normal;
        wc.point = p - r * slots[j].normal;
        wc.overlap = 0.0;
        wc.closing = true;
        next[n].wall = slots[j].wall;
        next[n].normal = slots[j].normal;
        next[n].history = slots[j].history;
        ++n;
      }
    slots = next;
    wall_held[s] = static_cast<std::uint8_t>((1u << n) - 1u);  // next holds slots 0 … n − 1
    wall_contact_n[s] = n;
  }
  for (int a = 0; a < na; ++a) {
    const int s = wall_active[a];
    if (ratio_s[a] > max_overlap_ratio) {
      max_overlap_ratio = ratio_s[a];
      max_overlap_what = wall_what(s_clump[s], walls[wall_contacts[a][0].wall].name);
      for (int k = 0; k < wall_contact_n[s]; ++k)
        if (wall_contacts[a][k].overlap / s_r[s] >= ratio_s[a])
          max_overlap_what = wall_what(s_clump[s], walls[wall_contacts[a][k].wall].name);
    }
    if (overflow[a] && !slot_overflow_warned) {
      slot_overflow_warned = true;
      warnings.push_back("a sphere touched more than " + std::to_string(kWallSlots) +
                         " separate wall regions at t = " + fmt_g(time) +
                         " s; the extra contacts were ignored");
    }
  }
}

template <class Pair, class Wall>
void World::Impl::visit_contacts(int c, Pair&& pair, Wall&& wall) const {
  for (int e = scratch_j_start[c]; e < scratch_j_start[c + 1]; ++e)
    pair(pair_contacts[scratch_j_list[e]], false);
  for (int k = scratch_i_start[c]; k < scratch_i_start[c + 1]; ++k) pair(pair_contacts[k], true);
  for (int s = c_first[c]; s < sphere_end(c); ++s)
    for (int k = 0; k < wall_contact_n[s]; ++k) wall(wall_contacts_of(s)[k]);
}

void World::Impl::compute_forces(double hdt) {
  const int nc = static_cast<int>(c_x.size());
  const int npc = static_cast<int>(pair_contacts.size());
  c_ww.resize(nc);
  c_vp.resize(nc);
  for (WallData& wd : walls) {
    wd.state.force.setZero();
    wd.state.torque.setZero();
  }
  const int na = static_cast<int>(wall_active.size());
  elastic = 0.0;
  const bool implicit = settings.implicit_damping > 0.0;
  if (implicit) c_damp.resize(nc);
  long n_implicit = 0;
  // Per-clump index of the pair contacts. The list is sorted by (i, j) and spheres by clump,
  // so clump c's contacts as sphere i are one range [i_start[c], i_start[c + 1]); its
  // contacts as sphere j (all before those, since j's clump comes after i's) are listed in
  // j_list[j_start[c] ...], in list order (a stable counting sort by j's clump, each thread
  // counting and filling its own block of the list).
  const bool parallel = npc + static_cast<int>(s_r.size()) >= kParallelMin;
  const int nt_all = parallel ? std::max(threads, 1) : 1;
  std::vector<int>& i_start = scratch_i_start;
  std::vector<int>& j_start = scratch_j_start;
  std::vector<int>& j_list = scratch_j_list;
  // The pair laws go out in blocks of the list; their energies are summed per block.
  constexpr int kBlock = 256;
  const int nblocks = (npc + kBlock - 1) / kBlock;
  std::vector<double>& block_energy = scratch_block_energy;
  block_energy.resize(nblocks);
  std::vector<std::vector<int>>& j_count = scratch_j_count;
  i_start.resize(nc + 1);
  j_start.resize(nc + 1);
  j_list.resize(npc);
  j_count.resize(nt_all);
  auto clump_i = [&](int k) { return pair_contact_clumps[k][0]; };
  auto clump_j = [&](int k) { return pair_contact_clumps[k][1]; };
  // The same thread that wrote a block of the contact list in detect_contacts (its geometry
  // and the pairs' histories are in that core's cache) indexes it and evaluates its laws.
  const std::vector<int>& cbs = contact_block_start;
  const bool aligned = static_cast<int>(cbs.size()) == nt_all + 1 && cbs[nt_all] == npc;
  // One parallel region: clump kinematics and the contact index, the pair and wall laws, then
  // the sums. Work goes to the threads statically, in contiguous ranges that stay with a
  // thread from stage to stage and step to step: shared out dynamically, most of what a stage
  // reads had last been written by the other core, and two threads were measured no faster
  // than one on the paper angle of repose (docs/dem.md). Every clump's sum is done by one
  // thread, visiting its contacts in list order (pairs by (i, j), then its spheres' wall
  // contacts by sphere), so it is the same sequence of additions for any thread count and
  // any division of the work.
#pragma omp parallel num_threads(nt_all) if (parallel) reduction(+ : n_implicit)
  {
    const int nt = omp_get_num_threads(), t = omp_get_thread_num();
    const int k0 = aligned ? cbs[t] : static_cast<int>(std::int64_t(npc) * t / nt);
    const int k1 = aligned ? cbs[t + 1] : static_cast<int>(std::int64_t(npc) * (t + 1) / nt);
#pragma omp for schedule(static) nowait
    for (int c = 0; c < nc; ++c) {
      c_ww[c] = c_R[c] * c_wb[c];
      // Predicted v(t) from the half-step velocity and the last forces, for the damping terms:
      // halves the restitution error at the default step (0.2 T_R).
      c_vp[c] = c_v[c] + (0.5 * dt) * (types[c_type[c]].inv_mass * c_f[c] + settings.gravity);
    }
    // The index, over this thread's block of the list: where each clump's i-range starts (a
    // clump c is written by the block holding the first contact with clump i >= c), and how
    // many contacts each clump has as j.
    std::vector<int>& count = j_count[t];
    count.assign(nc + 1, 0);
    for (int k = k0; k < k1; ++k) {
      const int ci = clump_i(k);
      for (int c = k == 0 ? 0 : clump_i(k - 1) + 1; c <= ci; ++c) i_start[c] = k;
      ++count[clump_j(k)];
    }
    if (t == nt - 1)
      for (int c = npc == 0 ? 0 : clump_i(npc - 1) + 1; c <= nc; ++c) i_start[c] = npc;
#pragma omp barrier
#pragma omp single
    {
      int at = 0;
      for (int c = 0; c < nc; ++c) {
        j_start[c] = at;
        for (int u = 0; u < nt; ++u) {
          const int n = j_count[u][c];
          j_count[u][c] = at;  // from here on: where thread u writes clump c's next entry
          at += n;
        }
      }
      j_start[nc] = at;
    }
    for (int k = k0; k < k1; ++k) j_list[count[clump_j(k)]++] = k;

    // Block b goes to the thread whose range holds its first contact.
    const int b0 = (k0 + kBlock - 1) / kBlock, b1 = (k1 + kBlock - 1) / kBlock;
    for (int b = b0; b < b1; ++b) {
      double block_elastic = 0.0;
      for (int k = b * kBlock; k < std::min(npc, (b + 1) * kBlock); ++k) {
        PairContactData& pc = pair_contacts[k];
        const PairEntry& p = pairs[pc.pair];
        const int ci = pair_contact_clumps[k][0], cj = pair_contact_clumps[k][1];
        const TypeData& ti = types[c_type[ci]];
        const TypeData& tj = types[c_type[cj]];
        const ResolvedContact& lw = law(ti.material, tj.material);
        const Eigen::Vector3d ri = pc.point - c_x[ci], rj = pc.point - c_x[cj];
        ContactKinematics kin;
        kin.normal = pc.normal;
        kin.overlap = pc.overlap;
        kin.r_star = s_r[p.i] * s_r[p.j] / (s_r[p.i] + s_r[p.j]);
        kin.m_star = ti.mass * tj.mass / (ti.mass + tj.mass);
        kin.radius_i = s_r[p.i];
        kin.radius_j = s_r[p.j];
        if (lw.rolling && lw.roll.model == RollingModel::kStandardCom) {
          kin.arm_i = ri.norm();
          kin.arm_j = rj.norm();
        }
        kin.omega_i = c_ww[ci];
        kin.omega_j = c_ww[cj];
        const Eigen::Vector3d spin_i = c_ww[ci].cross(ri), spin_j = c_ww[cj].cross(rj);
        kin.v_rel = (c_v[ci] + spin_i) - (c_v[cj] + spin_j);
        kin.v_rel_damping = (c_vp[ci] + spin_i) - (c_vp[cj] + spin_j);
        evaluate_contact(lw, kin, hdt, pair_hist[pc.pair], pc.out);
        pc.rolling = lw.rolling;
        block_elastic += pc.out.elastic_energy;
      }
      block_energy[b] = block_elastic;
    }

    // The wall laws, in the ranges of wall_active detect_contacts gave each thread.
#pragma omp for schedule(static)
    for (int a = 0; a < na; ++a) {
      const int s = wall_active[a];
      const int n = wall_contact_n[s];
      if (n == 0) continue;
      const int c = s_clump[s];
      const TypeData& ty = types[c_type[c]];
      for (int k = 0; k < n; ++k) {
        WallContactData& wc = wall_contacts[a][k];
        const WallData& wd = walls[wc.wall];
        const ResolvedContact& lw = law(ty.material, wd.material);
        const Eigen::Vector3d ri = wc.point - c_x[c];
        ContactKinematics kin;
        kin.normal = wc.normal;
        kin.overlap = wc.overlap;
        kin.r_star = s_r[s];
        kin.m_star = ty.mass;
        kin.radius_i = s_r[s];
        kin.radius_j = 0.0;
        if (lw.rolling && lw.roll.model == RollingModel::kStandardCom) kin.arm_i = ri.norm();
        kin.arm_j = 0.0;
        kin.omega_i = c_ww[c];
        kin.omega_j = wd.state.pose.omega;
        const Eigen::Vector3d vw = wd.state.pose.velocity_at(wc.point);
        const Eigen::Vector3d spin = c_ww[c].cross(ri);
        kin.v_rel = c_v[c] + spin - vw;
        kin.v_rel_damping = c_vp[c] + spin - vw;
        evaluate_contact(lw, kin, hdt, wall_slots[s][k].history, wc.out);
        wc.moment = ri.cross(wc.out.force);
        wc.wall_velocity = vw;
      }
    }

    // Sums (the loop above ends in a barrier, so every contact's force and the index are in
    // place), then the implicit damping of each clump that needs it. Contiguous ranges of
    // clumps of about equal work, counted as one per clump and two per pair contact held as
    // sphere i (each contact is summed on both of its sides, and over a range of clumps the j
    // sides are about as many as the i sides): where clumps were poured in order, the first
    // ones lie deepest in the bed, with the most contacts.
    auto work = [&](int c) { return std::int64_t(c) + 2 * std::int64_t(i_start[c]); };
    const std::int64_t w_all = work(nc);
    auto first_clump = [&](int u) {
      if (u == 0) return 0;
      if (u == nt) return nc;
      const std::int64_t target = w_all * u / nt;
      int lo = 0, hi = nc;  // the first clump whose work before it reaches the target
      while (lo < hi) {
        const int mid = (lo + hi) / 2;
        if (work(mid) < target)
          lo = mid + 1;
        else
          hi = mid;
      }
      return lo;
    };
    const int c_lo = first_clump(t), c_hi = first_clump(t + 1);
    for (int c = c_lo; c < c_hi; ++c) {
      Eigen::Vector3d f = Eigen::Vector3d::Zero(), tq = Eigen::Vector3d::Zero();
      double mroll = 0.0;
      Eigen::Vector2d load = Eigen::Vector2d::Zero();
      const TypeData& ty = types[c_type[c]];
      visit_contacts(
          c,
          [&](const PairContactData& pc, bool as_i) {
            // The force on sphere j is −force; each side has its own rolling torque.
            const Eigen::Vector3d r = pc.point - c_x[c];
            const Eigen::Vector3d fc = as_i ? pc.out.force : Eigen::Vector3d(-pc.out.force);
            f += fc;
            tq += r.cross(fc);
            if (implicit && (pc.out.dashpot_n > 0.0 || pc.out.dashpot_t > 0.0))
              load += 2.0 * dashpot_load(pc.out, ty, r, pc.normal);
            if (pc.rolling) {
              tq += as_i ? pc.out.torque_i : pc.out.torque_j;
              mroll += as_i ? pc.out.roll_i : pc.out.roll_j;
            }
          },
          [&](const WallContactData& wc) {
            f += wc.out.force;
            tq += wc.moment;
            if (law(ty.material, walls[wc.wall].material).rolling)
              tq += wc.out.torque_i, mroll += wc.out.roll_i;
            if (implicit) load += dashpot_load(wc.out, ty, wc.point - c_x[c], wc.normal);
          });
      c_f[c] = f;
      c_t[c] = tq;
      c_mroll[c] = mroll;
      if (implicit) {
        c_damp[c] = load;
        if (hdt > 0.0 && damp_implicitly(c)) ++n_implicit;
      }
    }
    // The contacts' energies, summed per block by the law loop, added in block order: the same
    // sum for any thread count.
#pragma omp single nowait
    {
      for (int b = 0; b < nblocks; ++b) elastic += block_energy[b];
      for (int a = 0; a < na; ++a)
        for (int k = 0; k < wall_contact_n[wall_active[a]]; ++k) {
          const WallContactData& wc = wall_contacts[a][k];
          WallData& wd = walls[wc.wall];
          const Eigen::Vector3d& f = wc.out.force;
          wd.state.force -= f;
          wd.state.torque -= (wc.point - wd.state.torque_reference).cross(f);
          elastic += wc.out.elastic_energy;
          wall_work += f.dot(wc.wall_velocity) * hdt;
        }
    }
  }
  if (hdt > 0.0) {
    profile.clump_steps += nc;
    profile.implicit_clump_steps += n_implicit;
  }
}

// Implicit damping of clump c if its dashpot load is above the gate (its loads are in c_damp,
// its summed force and torque in c_f, c_t): its own velocity enters its damping implicitly
// (backward Euler), the neighbours' explicitly. The step then applies F_eff = M (M + w dt C)^-1 F,
// with C the clump's damping matrix and F its whole force and torque (gravity included, so a clump
// at rest stays at rest). Explicit damping overshoots above a rate of about 1/step; this cannot
// (docs/dem.md). Returns whether the clump was treated.
bool World::Impl::damp_implicitly(int c) {
  if (!(c_damp[c].x() * dt > settings.implicit_damping ||
        c_damp[c].y() * dt > kTangentialGate * settings.implicit_damping))
    return false;
  // C from the clump's contacts, in the order of the sums (compute_forces).
  Matrix6d cm = Matrix6d::Zero();
  visit_contacts(
      c,
      [&](const PairContactData& pc, bool) {
        if (pc.out.dashpot_n != 0.0 || pc.out.dashpot_t != 0.0)
          add_dashpots(cm, pc.point - c_x[c], pc.normal, pc.out.dashpot_n, pc.out.dashpot_t);
      },
      [&](const WallContactData& wc) {
        add_dashpots(cm, wc.point - c_x[c], wc.normal, wc.out.dashpot_n, wc.out.dashpot_t);
      });
  // (M + w dt C) y = F in world coordinates, M = diag(m, m, m, R I Rᵀ); F_eff = M y.
  const TypeData& ty = types[c_type[c]];
  const Eigen::Matrix3d inertia = c_R[c] * ty.inertia.asDiagonal() * c_R[c].transpose();
  // The normal impulse is telescoped over two steps and the damping velocity is
  // extrapolated: in a pure dashpot the scheme's fastest (alternating) mode responds to up to
  // twice the coefficient, and the filter with C alone lets it grow once Γ dt is a few units.
  // C is weighted w = 1 + σ/(1 + σ) (σ = the clump's load × dt ≥ Γ dt): about 1 for gentle
  // contacts, 2 for stiff jams (a scalar model of both schemes is stable for every Γ dt with
  // this weight: bench/damping_schemes.py).
  const double sigma = c_damp[c].maxCoeff() * dt;
  Matrix6d a = (dt * (1.0 + sigma / (1.0 + sigma))) * cm;
  a.diagonal().head<3>().array() += ty.mass;
  a.bottomRightCorner<3, 3>() += inertia;
  Vector6d f;
  f.head<3>() = c_f[c] + ty.mass * settings.gravity;
  f.tail<3>() = c_t[c];
  const Vector6d y = solve_spd(a, f);
  c_f[c] = ty.mass * y.head<3>() - ty.mass * settings.gravity;
  c_t[c] = inertia * y.tail<3>();
  return true;
}

void World::Impl::release_pinched(World& world) {
  if (max_overlap_ratio <= settings.pinch_release) return;
  const int nc = static_cast<int>(c_x.size());
  const int ns = static_cast<int>(s_r.size());
  // Only a moving wall can pinch, and it pinches through the pills it presses on: a clump is
  // released where it is loaded by a wall that moves now (it touches one, or touches a clump
  // that is loaded: a settled bed under a scraper is one chain) and is squeezed by a wall or
  // another clump. A deep contact among clumps that no moving wall loads is a hard landing
  // (soft pills poured into a heap while every wall rests), left to the overlap check;
  // releasing those took up to half of a soft mini heap (docs/rigs.md). Releasing only the
  // clumps that touch the moving wall themselves (session 50) left a pill wedged by the one the
  // scraper pushes against the cup's rim, and two of nine Table-1 cups at mini blew up.
  const int nw = static_cast<int>(walls.size());
  std::vector<char> moving(nw, 0);
  bool any_moving = false;
  for (int k = 0; k < nw; ++k) {
    const WallPose& p = walls[k].state.pose;
    moving[k] = p.velocity.squaredNorm() > 0.0 || p.omega.squaredNorm() > 0.0;
    any_moving = any_moving || moving[k];
  }
  if (!any_moving) return;
  // The clumps a moving wall loads: the groups of touching clumps (union-find over this step's
  // pair contacts) that hold a clump touching such a wall.
  std::vector<int> group(nc);
  for (int c = 0; c < nc; ++c) group[c] = c;
  auto root = [&](int c) {
    while (group[c] != c) c = group[c] = group[group[c]];
    return c;
  };
  for (const PairContactData& pc : pair_contacts) {
    const PairEntry& p = pairs[pc.pair];
    const int a = root(s_clump[p.i]), b = root(s_clump[p.j]);
    if (a != b) group[std::max(a, b)] = std::min(a, b);
  }
  std::vector<char> group_held(nc, 0);
  for (int s = 0; s < ns; ++s)
    for (int k = 0; k < wall_contact_n[s]; ++k)
      if (moving[wall_contacts_of(s)[k].wall]) group_held[root(s_clump[s])] = 1;
  std::vector<char> held(nc, 0);
  for (int c = 0; c < nc; ++c) held[c] = group_held[root(c)];
  auto pair_ratio = [&](const PairContactData& pc) {
    const PairEntry& p = pairs[pc.pair];
    return pc.overlap / std::min(s_r[p.i], s_r[p.j]);
  };
  // Both clumps of a pinched pair go: the chain wall → pill → pill → wall is broken either way.
  std::vector<char> out(nc, 0);
  std::string first;
  double first_ratio = 0.0;
  for (const PairContactData& pc : pair_contacts) {
    const PairEntry& p = pairs[pc.pair];
    const double ratio = pair_ratio(pc);
    if (ratio <= settings.pinch_release) continue;
    const int ci = s_clump[p.i], cj = s_clump[p.j];
    if (!held[ci] && !held[cj]) continue;
    if (ratio > first_ratio) first_ratio = ratio, first = "against another clump";
    out[ci] = out[cj] = 1;
  }
  for (int s = 0; s < ns; ++s)
    for (int k = 0; k < wall_contact_n[s]; ++k) {
      const WallContactData& wc = wall_contacts_of(s)[k];
      const double ratio = wc.overlap / s_r[s];
      if (ratio <= settings.pinch_release) continue;
      if (!moving[wc.wall] && !held[s_clump[s]]) continue;
      if (ratio > first_ratio)
        first_ratio = ratio, first = "against wall '" + walls[wc.wall].name + "'";
      out[s_clump[s]] = 1;
    }
  if (first.empty()) return;
  // The deepest contact that stays (both its clumps stay) is this step's overlap check's (the
  // clumps named by their indices before the removal, as the detection named them).
  double kept = 0.0;
  std::string kept_what;
  for (const PairContactData& pc : pair_contacts) {
    const PairEntry& p = pairs[pc.pair];
    const int ci = s_clump[p.i], cj = s_clump[p.j];
    const double ratio = pair_ratio(pc);
    if (!out[ci] && !out[cj] && ratio > kept) kept = ratio, kept_what = clumps_what(ci, cj);
  }
  for (int s = 0; s < ns; ++s)
    for (int k = 0; k < wall_contact_n[s]; ++k) {
      const WallContactData& wc = wall_contacts_of(s)[k];
      const double ratio = wc.overlap / s_r[s];
      if (!out[s_clump[s]] && ratio > kept)
        kept = ratio, kept_what = wall_what(s_clump[s], walls[wc.wall].name);
    }
  int n = 0;
  double m = 0.0;
  for (int c = 0; c < nc; ++c)
    if (out[c]) ++n, m += types[c_type[c]].mass;
  if (pinched_count == 0)
    warnings.push_back("a clump was pinched " + first + " at t = " + fmt_g(time) + " s (overlap " +
                       fmt_g(100.0 * first_ratio) +
                       " % of a sphere radius, above the pinch release " +
                       fmt_g(100.0 * settings.pinch_release) +
                       " %) and was taken out of the run; later ones are only counted");
  pinched_count += n;
  pinched_mass += m;
  world.remove_clumps([&](int c) { return out[c] != 0; });
  max_overlap_ratio = kept;
  max_overlap_what = kept_what;
}

void World::Impl::check_health() {
  auto fail = [&](const std::string& what) {
    throw NumericalError("step " + std::to_string(steps) + ", t = " + fmt_g(time) + " s: " + what +
                         " (time step " + fmt_g(dt) + " s)");
  };
  if (max_overlap_ratio > 0.5)
    fail("overlap of " + fmt_g(100.0 * max_overlap_ratio) + " % of a sphere radius between " +
         max_overlap_what +
         ": spheres are passing through each other or a wall (time step too large, wall too "
         "fast, or too soft a material)");
  if (steps % settings.check_interval != 0) return;
  const int nc = static_cast<int>(c_x.size());
  for (int c = 0; c < nc; ++c) {
    if (!c_x[c].allFinite() || !c_v[c].allFinite() || !c_wb[c].allFinite())
      fail("clump " + std::to_string(c) +
           " has a non-finite position or velocity: the run blew up");
    if (c_v[c].norm() > settings.max_speed)
      fail("clump " + std::to_string(c) + " moves at " + fmt_g(c_v[c].norm()) +
           " m/s, above max_speed " + fmt_g(settings.max_speed) + " m/s: the run blew up");
  }
  const double ke = kinetic_energy();
  const double e = ke + potential_energy() + elastic;
  const double excess = e - (check_energy + wall_work + inserted_energy);
  double floor = 1e-12;
  for (int c = 0; c < nc; ++c) floor += types[c_type[c]].mass * settings.gravity.norm() * r_min;
  const double scale =
      check_ke + std::abs(check_elastic) + std::abs(wall_work) + std::abs(inserted_energy) + floor;
  if (excess > scale)
    fail("energy jumped by " + fmt_g(excess) + " J in " + std::to_string(settings.check_interval) +
         " steps with no source (kinetic " + fmt_g(check_ke) + " -> " + fmt_g(ke) + " J, elastic " +
         fmt_g(check_elastic) + " -> " + fmt_g(elastic) + " J, work by walls " + fmt_g(wall_work) +
         " J): the contact forces are unstable");
  check_energy = e;
  check_ke = ke;
  check_elastic = elastic;
  wall_work = inserted_energy = 0.0;
}

}  // namespace clumpkit::dem
