#pragma once
// Internal state of dem::World. Hot per-instance data are arrays indexed by clump or sphere;
// template data are shared per clump type.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "clumpkit/dem/world.hpp"

namespace clumpkit::dem {

/// A number in messages: four significant digits (printf %.4g).
std::string fmt_g(double v);

/// Template data shared by every clump of one type (principal frame).
struct TypeData {
  std::vector<Eigen::Vector3d> offsets;  // sphere centres relative to the centre of mass, m
  std::vector<double> radii;             // m
  double mass = 0.0;                     // kg
  Eigen::Vector3d inertia = Eigen::Vector3d::Zero();      // principal moments, kg m^2
  double inv_mass = 0.0;                                  // 1 / mass, for the integrator
  Eigen::Vector3d inv_inertia = Eigen::Vector3d::Zero();  // 1 / principal moments
  double bound_radius = 0.0;                              // max |offset| + radius, m
  double volume = 0.0;                                    // union volume, m^3
  int material = 0;
};

struct WallData {
  std::string name;
  int material = 0;
  std::vector<Eigen::Vector3d> ref_vertices;  // at t = 0
  std::vector<std::array<int, 3>> triangles;
  std::vector<Eigen::Vector3d> ref_normals;  // unit face normals at t = 0 (zero if degenerate)
  WallMotion motion;
  Eigen::Vector3d torque_reference0 = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> vertices;        // current
  std::vector<Eigen::Vector3d> normals;         // current unit face normals
  bool normals_turned = false;                  // normals differ from ref_normals
  std::vector<Eigen::Vector3d> vertices_build;  // at the last neighbour rebuild
  WallState state;
};

struct PairEntry {
  int i = 0, j = 0;  // sphere indices, i < j, different clumps
  // The list's order: by i, then j (the rebuild sorts it so; the history carry-over and the
  // search before a rebuild rely on it).
  friend bool operator<(const PairEntry& a, const PairEntry& b) {
    return a.i < b.i || (a.i == b.i && a.j < b.j);
  }
  friend bool operator==(const PairEntry& a, const PairEntry& b) {
    return a.i == b.i && a.j == b.j;
  }
};

// Geometry of an active sphere-sphere contact (contacts stage) and its result (forces stage).
struct PairContactData {
  int pair = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double overlap = 0.0;
  bool closing = false;  // overlap gone, last damping impulse only (contact_law.hpp)
  bool rolling = false;  // the pair's law has rolling resistance (forces stage)
  ContactForce out;
};

inline constexpr int kWallSlots = 4;  // wall contacts kept per sphere
// Loops shorter than this run on one thread: a parallel region costs more than it saves, and a
// lot more on a loaded machine. Results do not depend on it (see determinism tests).
inline constexpr int kParallelMin = 512;
// With threads = 0 (auto) a scene runs on one thread below this many spheres: OpenMP barriers
// cost more than they save there, and far more when the machine is shared (see docs/dem.md).
inline constexpr long kAutoThreadsMin = 20000;

struct WallSlot {
  int wall = -1;  // −1 = unused
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  ContactHistory history;
};

struct WallContactData {
  int wall = -1;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double overlap = 0.0;
  bool closing = false;  // overlap gone, last damping impulse only (contact_law.hpp)
  ContactForce out;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();         // (point − clump centre) × force
  Eigen::Vector3d wall_velocity = Eigen::Vector3d::Zero();  // wall material at the point
};

struct FactoryRuntime {
  FactorySettings s;
  std::vector<int> types;
  std::vector<double> fractions;  // normalised mass fractions
  std::vector<double> type_mass;  // kg inserted per mixture entry
  FactoryStatus status;
  std::mt19937_64 rng;
  long batch = 0;         // next batch index
  double interval = 0.0;  // s
};

using Clock = std::chrono::steady_clock;

struct World::Impl {
  WorldSettings settings;
  double dt = 0.0;
  double time = 0.0;
  long steps = 0;
  int threads = 1;      // threads used by the current step
  int max_threads = 1;  // all cores, for threads = 0 (auto)
  std::vector<std::string> warnings;
  Profile profile;

  std::vector<Material> materials;
  std::map<std::string, int> material_index;
  std::vector<ResolvedContact> laws;  // [a * nm + b]
  std::vector<TypeData> types;

  // Clumps (structure of arrays).
  std::vector<int> c_type, c_first;
  std::vector<Eigen::Vector3d> c_x, c_v, c_wb;  // wb: angular velocity, principal frame
  std::vector<Eigen::Quaterniond> c_q;          // body → world
  std::vector<Eigen::Matrix3d> c_R;             // rotation matrix of c_q
  std::vector<Eigen::Vector3d> c_f, c_t;        // contact force / torque (no rolling), world
  std::vector<double> c_mroll;                  // standard rolling resistance: Σ μr R |Fn|, N m
  std::vector<Eigen::Vector3d> c_ww;            // world angular velocity (scratch)
  std::vector<Eigen::Vector3d> c_vp;            // predicted v(t) for damping (scratch)
  std::vector<Eigen::Vector2d> c_damp;  // implicit damping: normal, tangential dashpot load, 1/s

  // Sub-spheres.
  std::vector<int> s_clump;
  std::vector<double> s_r;
  std::vector<Eigen::Vector3d> s_off;  // body-frame offset (copied from the type)
  std::vector<Eigen::Vector3d> s_pos, s_pos_build;

  std::vector<WallData> walls;

  // Neighbour lists: sphere pairs sorted by (i, j) with their histories; per-sphere wall
  // candidates (wall, triangle) in CSR form; per-sphere wall contact histories.
  std::vector<PairEntry> pairs;
  std::vector<ContactHistory> pair_hist;
  // Per listed pair: 1 if its history may be non-empty (it touched or was closing at the last
  // detection), so detect_contacts reads the history of an apart pair only then. Rebuilt from
  // the histories by detect_contacts when its size differs from the list's (cleared by a
  // rebuild, a checkpoint load and removals).
  std::vector<std::uint8_t> pair_live;
  std::vector<int> wall_cand_start;
  std::vector<std::array<int, 2>> wall_cand;
  // Per wall, its triangles binned by cell in the wall's own frame (its vertices at t = 0): a
  // wall moves rigidly, so the bins are built once and a sphere is looked up at its position
  // carried back into that frame.
  std::vector<std::vector<std::pair<std::uint64_t, int>>> tri_bins;
  bool tri_bins_valid = false;
  std::vector<std::array<WallSlot, kWallSlots>> wall_slots;
  // Per sphere, bit k set if wall_slots[s][k] is held (wall >= 0): the detection reads this
  // byte instead of the four slots (~350 bytes) of every sphere near a wall. Kept with the
  // slots (detect_contacts, add_clump); recount_wall_held after they are replaced wholesale.
  std::vector<std::uint8_t> wall_held;
  void recount_wall_held() {
    wall_held.assign(wall_slots.size(), 0);
    for (size_t s = 0; s < wall_slots.size(); ++s)
      for (int k = 0; k < kWallSlots; ++k)
        if (wall_slots[s][k].wall >= 0) wall_held[s] |= std::uint8_t(1u << k);
  }
  // Spheres with wall candidates or a wall contact history, ascending: the only spheres the
  // wall stages visit. Refreshed at every rebuild and whenever marked dirty (clumps added or
  // removed, a checkpoint loaded).
  std::vector<int> wall_active;
  bool wall_active_dirty = true;
  bool need_rebuild = true;
  // The two largest squared sphere displacements since the rebuild that belong to different
  // clumps (a clump's own spheres are never paired), measured by kick_and_drift for the
  // update_neighbours that follows it (m^2).
  struct TopTwo {
    double first = 0.0, second = 0.0;
    void add(double x) {
      if (x > first) {
        second = first;
        first = x;
      } else if (x > second) {
        second = x;
      }
    }
  };
  TopTwo drift_disp2;
  bool drift_disp_valid = false;
  // Per clump, its spheres' largest squared displacement since the rebuild (m^2), beside
  // drift_disp2 (valid with it): pair_list_complete reads which clumps moved far.
  std::vector<double> c_disp2;
  double skin = 0.0, cell = 0.0, r_max = 0.0, r_min = 0.0;

  // Contacts of the current step.
  std::vector<PairContactData> pair_contacts;
  // The two clumps of each pair contact (i's, j's), beside the list: the forces' index reads
  // them for every contact, and a PairContactData is ~230 bytes.
  std::vector<std::array<int, 2>> pair_contact_clumps;
  // Wall contacts of the current step, one row per sphere of wall_active (the only spheres
  // that can have any): a row per sphere made this a ~1 kB stride over every sphere, 40 MB at
  // paper scale, which the wall stages walked through cache-missing. wall_row[s] is sphere s's
  // row (−1 outside wall_active); wall_contact_n[s] its count (0 outside wall_active).
  std::vector<std::array<WallContactData, kWallSlots>> wall_contacts;
  std::vector<int> wall_row;
  std::vector<int> wall_contact_n;
  std::array<WallContactData, kWallSlots>& wall_contacts_of(int s) {
    return wall_contacts[wall_row[s]];
  }
  const std::array<WallContactData, kWallSlots>& wall_contacts_of(int s) const {
    return wall_contacts[wall_row[s]];
  }
  bool forces_valid = false;
  double elastic = 0.0;
  double max_overlap_ratio = 0.0;
  std::string max_overlap_what;
  bool slot_overflow_warned = false;
  // A thread's own scratch vector, on cache lines of its own: side by side in one array, the
  // threads' vectors would share a line whose end pointers each push_back writes.
  template <class T>
  struct alignas(64) PerThread {
    std::vector<T> v;
  };
  // Per-step scratch of detect_contacts (kept to avoid reallocation).
  std::vector<double> scratch_ratio;
  std::vector<PerThread<std::array<int, 2>>> scratch_found;      // per thread, rebuild_neighbours
  std::vector<int> scratch_start, scratch_fill;                  // rebuild_neighbours
  std::vector<std::vector<std::array<int, 2>>> scratch_cand;     // per sphere, rebuild_neighbours
  std::vector<std::pair<std::uint64_t, int>> scratch_bins;       // rebuild_neighbours
  std::vector<std::pair<int, double>> scratch_moved;             // pair_list_complete
  std::vector<int> scratch_fast;                                 // pair_list_complete
  std::vector<PerThread<std::pair<int, double>>> scratch_touch;  // per thread: pair, distance
  // Where each thread's block of pair_contacts starts (threads + 1 entries, the last the
  // count), as detect_contacts wrote them; compute_forces evaluates them on the same threads.
  std::vector<int> contact_block_start;
  std::vector<std::pair<double, int>> scratch_max;  // per thread: overlap ratio, pair
  std::vector<int> scratch_overflow;
  // Per-step scratch of compute_forces: each clump's pair contacts (as sphere i: a range of
  // the list; as sphere j: indices in list order), per-thread counts, energy partial sums.
  std::vector<int> scratch_i_start, scratch_j_start, scratch_j_list;
  std::vector<std::vector<int>> scratch_j_count;
  std::vector<double> scratch_block_energy;

  std::vector<FactoryRuntime> factories;

  // Energy bookkeeping for blow-up detection.
  double check_energy = 0.0;  // KE + PE + elastic at the last check
  double check_ke = 0.0;
  double check_elastic = 0.0;
  int pinched_count = 0;         // clumps taken out by the pinch release
  double pinched_mass = 0.0;     // kg
  double wall_work = 0.0;        // J done by walls on particles since the last check
  double inserted_energy = 0.0;  // J brought in by factories since the last check
  bool check_initialised = false;

  std::uint64_t fingerprint = 0;

  // Stages (step.cpp).
  void ensure_forces();
  void kick_and_drift();
  void move_walls();
  void run_factories();
  void update_neighbours();
  void detect_contacts();
  void compute_forces(double history_dt);
  void kick();
  void check_health();
  bool damp_implicitly(int c);  // step.cpp, in the forces' sums
  void release_pinched(World& world);
  void update_spheres(int first_clump);

  // Helpers.
  /// One past clump c's last sphere (its spheres are s in [c_first[c], sphere_end(c))).
  int sphere_end(int c) const {
    return c + 1 < static_cast<int>(c_first.size()) ? c_first[c + 1] : static_cast<int>(s_r.size());
  }
  /// Visits clump c's contacts of the last detection in the order of its force sum: its pair
  /// contacts as sphere j, then as sphere i (each in list order; the index compute_forces
  /// builds), then its spheres' wall contacts. pair(pc, as_i), wall(wc). step.cpp.
  template <class Pair, class Wall>
  void visit_contacts(int c, Pair&& pair, Wall&& wall) const;
  const ResolvedContact& law(int ma, int mb) const {
    return laws[static_cast<size_t>(ma) * materials.size() + mb];
  }
  int add_clump(int type, const Eigen::Vector3d& x, const Eigen::Quaterniond& q,
                const Eigen::Vector3d& v, const Eigen::Vector3d& w_world);
  double kinetic_energy() const;
  double potential_energy() const;
  void rebuild_neighbours();
  /// Whether every sphere pair touching now is in the list, where the displacement bound fired
  /// (d1: the largest clump displacement since the rebuild, m). neighbours.cpp.
  bool pair_list_complete(double d1);
  void refresh_wall_active();
  std::uint64_t compute_fingerprint() const;
};

/// x + R o, the position of a sphere at body offset o, written out: Eigen's `x + R * o` called
/// its generic product kernel once per sphere. Associated as Eigen associates it (rows 0 and 1
/// as (a + b) + c, row 2 as a + (b + c); checked by DemKernels.SpherePositionIsEigensProduct),
/// so positions keep their bits.
inline Eigen::Vector3d sphere_position(const Eigen::Vector3d& x, const Eigen::Matrix3d& R,
                                       const Eigen::Vector3d& o) {
  return {x.x() + ((R(0, 0) * o.x() + R(0, 1) * o.y()) + R(0, 2) * o.z()),
          x.y() + ((R(1, 0) * o.x() + R(1, 1) * o.y()) + R(1, 2) * o.z()),
          x.z() + (R(2, 0) * o.x() + (R(2, 1) * o.y() + R(2, 2) * o.z()))};
}

/// Whether a contact history holds anything (springs or a pending damping impulse).
inline bool history_empty(const ContactHistory& h) {
  return h.damping == 0.0 && h.shear.isZero(0.0) && h.roll.isZero(0.0);
}

/// FNV-1a over raw bytes.
struct Hasher {
  std::uint64_t h = 1469598103934665603ull;
  void bytes(const void* p, size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (size_t k = 0; k < n; ++k) {
      h ^= b[k];
      h *= 1099511628211ull;
    }
  }
  template <class T>
  void value(const T& v) {
    bytes(&v, sizeof v);
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    value(v.size());
    if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
  }
};

/// Closest point on triangle (a, b, c) to p.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// True if p is at least `reach` from the plane of wall triangle `tri` (current vertices and
/// normals), so at least that far from the triangle: the cheap test before the closest point.
/// A degenerate triangle's zero normal never rejects.
inline bool beyond_plane(const WallData& wd, int tri, const Eigen::Vector3d& p, double reach) {
  return std::abs((p - wd.vertices[wd.triangles[tri][0]]).dot(wd.normals[tri])) >= reach;
}

}  // namespace clumpkit::dem
