#pragma once
/// Insertion of clumps: box (optionally cut by planes) or cylinder regions, by count or mass, all
/// at once or at a rate, random positions and orientations, non-overlapping, template mixture by
/// mass fraction.
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace clumpkit::dem {

/// The side of a plane that `normal` points into (LIGGGHTS' `region plane`, `side in`).
struct HalfSpace {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    ///< a point of the plane, m
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, into the kept side
};

/// A box region takes at most this many cuts (each is tested for every placement tried).
inline constexpr size_t kMaxRegionCuts = 16;

struct BoxRegion {
  BoxRegion() = default;
  BoxRegion(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, std::vector<HalfSpace> c = {})
      : min(lo), max(hi), cuts(std::move(c)) {}
  Eigen::Vector3d min = Eigen::Vector3d::Zero();  ///< m
  Eigen::Vector3d max = Eigen::Vector3d::Zero();  ///< m
  /// The region is the part of the box inside every one of these (e.g. a hopper's inclined
  /// walls, so that no clump is placed beyond them); none = the whole box.
  std::vector<HalfSpace> cuts;
};

/// Axis +z through `base_center`.
struct CylinderRegion {
  Eigen::Vector3d base_center = Eigen::Vector3d::Zero();  ///< m
  double radius = 0.0;                                    ///< m
  double height = 0.0;                                    ///< m
};

using Region = std::variant<BoxRegion, CylinderRegion>;

/// Exact for boxes and cylinders; a box with cuts is integrated on a 64³ midpoint grid (within
/// 1 % of the closed form for the V-cut box of World.FactoryKeepsEveryPillInsideABoxsCuts).
double region_volume(const Region& r);
std::string describe(const Region& r);  ///< e.g. "box 20 x 20 x 20 mm"
/// Whether `p` lies in the region at least `margin` from its boundary (margin 0: in it at all).
bool region_contains(const Region& r, const Eigen::Vector3d& p, double margin = 0.0);

struct MixtureEntry {
  std::string clump_type;
  double mass_fraction = 1.0;  ///< normalised over the mixture
};

struct FactorySettings {
  std::string name = "factory";
  Region region = BoxRegion{};
  std::vector<MixtureEntry> mixture;
  std::optional<long> count;   ///< clumps to insert; exactly one of count and mass
  std::optional<double> mass;  ///< kg to insert (stops at the clump that comes closest)
  /// 0 = everything at start_time (an InputError when the region cannot hold it); otherwise
  /// clumps/s (with count) or kg/s (with mass), inserted in batches every `interval`.
  double rate = 0.0;
  double start_time = 0.0;  ///< s
  double interval = 0.0;    ///< s between batches; 0 = the free-fall time of the region
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< initial velocity, m/s
  bool random_orientation = true;
  /// true: every sphere of an inserted clump lies inside the region (LIGGGHTS' `all_in yes`);
  /// false: only its centre of mass does (LIGGGHTS' default, `all_in no`): a small region then
  /// holds several times more clumps per batch, which protrude from it by up to their bounding
  /// radius (walls and other clumps are still never overlapped).
  bool whole_in_region = true;
  int attempts_per_clump = 200;  ///< random placements tried before giving up on a clump
  /// With a rate: true = an InputError when the region stays full and the factory falls more
  /// than two batches behind (a scene asked for more than its region can deliver); false = pour
  /// as fast as the region allows, carrying the deficit (the rigs: they need the mass, not the
  /// rate). Such a factory ends when a whole batch fits nothing (its region is blocked).
  bool fail_if_behind = true;
  /// With a rate and fail_if_behind = false, the factory also ends after a batch that could not
  /// place all it was due and placed less than this fraction of one batch at the rate (rate ×
  /// interval): its region is nearly full and only trickles (the rigs' column fill hands the
  /// rest to the pour from above). 0 = end only when a batch places nothing.
  double end_below = 0.0;
};

/// What a factory has done so far.
struct FactoryStatus {
  long inserted = 0;
  double inserted_mass = 0.0;  ///< kg
  bool done = false;
  long failed_attempts = 0;  ///< placements rejected (overlap, or no point inside the cuts)
};

}  // namespace clumpkit::dem
