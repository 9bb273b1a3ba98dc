#pragma once
/// Wall-clock time spent in each stage of World::step, for the per-stage profile print.
#include <string>

namespace clumpkit::dem {

struct Profile {
  double integrate = 0.0;   ///< s, both velocity-Verlet halves
  double walls = 0.0;       ///< s, wall motion
  double insert = 0.0;      ///< s, factories
  double neighbours = 0.0;  ///< s, cell lists and Verlet lists
  double contacts = 0.0;    ///< s, sphere-sphere and sphere-triangle detection
  double forces = 0.0;      ///< s, contact law and accumulation
  double checks = 0.0;      ///< s, blow-up detection
  double output = 0.0;      ///< s, filled in by callers that write files
  long steps = 0;
  long neighbour_rebuilds = 0;
  /// Steps at which the displacement bound called for a rebuild and a search of the last
  /// rebuild's cells found every touching pair already listed (no rebuild made).
  long neighbour_rebuilds_spared = 0;
  /// Implicit damping (WorldSettings::implicit_damping): clump-steps in all, and those whose
  /// damping was integrated implicitly.
  long clump_steps = 0;
  long implicit_clump_steps = 0;

  double total() const {
    return integrate + walls + insert + neighbours + contacts + forces + checks + output;
  }
  /// A small table: stage, seconds, share.
  std::string table() const;
};

}  // namespace clumpkit::dem
