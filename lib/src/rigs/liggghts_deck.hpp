#pragma once
/// A rig as a LIGGGHTS 3.8 input deck, for runs that outgrow one machine (`clumpkit rig ...
/// --engine liggghts --np N` runs it under MPI). The deck is built from the same engine settings
/// the bundled runner gets (dem::WorldSettings: materials, contact laws, clump templates, walls,
/// factories), so both codes see one scene; the rig's procedure (pour, settle by the speed
/// criterion, the action, settle) becomes LIGGGHTS script loops. Where LIGGGHTS cannot express an
/// effect the deck says what it used instead (LiggghtsDeck::notes).
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "clumpkit/dem/world.hpp"

namespace clumpkit::rigs::detail {

/// One file of a deck (the input script, an STL wall, a template's spheres), name relative to
/// the run folder.
struct DeckFile {
  std::string name, content;
};

class LiggghtsDeck {
 public:
  /// The scene: simulation box `domain` (pills leaving it are dropped), time step `dt` (s), the
  /// materials and per-pair laws of `ws` (Hertz–Mindlin with history; CDT or EPSD2 rolling
  /// friction; SJKR cohesion), gravity, every wall of `ws` at rest (ASCII STL), the clump
  /// templates with their union mass and inertia, and the multisphere integrator. `seed` gives
  /// LIGGGHTS's prime seeds. Walls must lie inside `domain`. Spheres below `floor_z` (m) have
  /// left the rig: the settle criterion leaves them out.
  LiggghtsDeck(const dem::WorldSettings& ws, const Eigen::AlignedBox3d& domain, double floor_z,
               double dt, std::uint64_t seed, const std::string& title);

  /// Inserts factory `f` (its mixture of the clump types): everything at once (`insert/pack`)
  /// when f.rate is 0, else `insert/rate/region` at f.rate in batches a free fall of the region
  /// apart. Returns the simulated seconds the insertion lasts (0 for all at once).
  /// `mass_variable`, if given, names a script variable holding the mass to insert instead of
  /// f.mass (a top-up of what an earlier insertion could not place).
  double insert(const dem::FactorySettings& f, const std::string& mass_variable = "");
  /// Ends the last insertion as the bundled runner's rig factories end: once the mass is in
  /// (within `tolerance` kg) or a batch places nothing more; LIGGGHTS would otherwise keep
  /// placing a pill now and then into the settling bed. Runs batch by batch until then.
  /// Returns the name of the script variable holding the mass it placed, kg.
  std::string finish_insertion(double tolerance);
  /// Runs `seconds` of simulated time, printing progress (`what`) about every 2 % of it;
  /// `seconds` may be a script expression ("${lift}/0.03").
  void run(double seconds, const std::string& what);
  void run(const std::string& seconds, const std::string& what);
  /// The lines added from begin_block() to end_block(name, condition) run only when the
  /// script's `condition` holds ("${short} > 0.001"): they go to the file `name`, which the
  /// main script jumps to and which jumps back.
  void begin_block() { block_start_ = lines_.size(); }
  void end_block(const std::string& name, const std::string& condition);
  /// The rigs' settle criterion as a script loop: runs in checks `check` s apart until the RMS
  /// sphere speed stays below `speed` (m/s) for 3 checks, or `max_seconds` have passed.
  void settle(const std::string& what, double speed, double max_seconds, double check = 0.01);
  /// Starts wall `name` moving at velocity `v` (m/s) / stops it.
  void move_wall(const std::string& name, const Eigen::Vector3d& v);
  void stop_wall(const std::string& name);
  /// Starts wall `name` turning at `rpm` about the axis through `point` along `axis`
  /// (right-handed; the bundled runner's WallRotation).
  void rotate_wall(const std::string& name, const Eigen::Vector3d& point,
                   const Eigen::Vector3d& axis, double rpm);
  /// Writes the clumps (centre of mass and mass, `bodies_file`) and the spheres (centre and
  /// radius, `spheres_file`) once, at the current step.
  void write_state(const std::string& bodies_file, const std::string& spheres_file);
  /// Writes the clumps only (centre of mass and mass), once, at the current step.
  void write_bodies(const std::string& bodies_file);
  void line(const std::string& l) { lines_.push_back(l); }

  /// The input script and every file it reads.
  std::vector<DeckFile> files() const;
  /// Where the deck differs from the bundled runner's physics (for the result's details).
  const std::vector<std::string>& notes() const { return notes_; }
  double dt() const { return dt_; }

 private:
  long steps(double seconds) const;
  std::uint64_t next_prime();

  std::vector<std::string> lines_;
  std::vector<DeckFile> files_;
  std::vector<std::string> notes_;
  std::vector<std::string> template_ids_;  // per clump type of the settings
  std::vector<std::string> type_names_;
  std::vector<double> type_volumes_;
  double dt_ = 0.0;
  std::uint64_t prime_ = 10007;
  int factories_ = 0, loops_ = 0;
  size_t block_start_ = 0;
  bool body_computes_ = false;
  std::string last_target_;  // the last insertion's mass (a number or a ${variable})
  long last_interval_ = 0;   // its batches' interval, steps (0: all at once)
};

/// A LIGGGHTS dump (`dump local` of the clumps or `dump custom` of the spheres): the rows of
/// its last frame, numbers by column. Throws InputError naming the file on a malformed dump.
std::vector<std::vector<double>> read_dump_rows(const std::string& path, int columns);
/// The same, and the frame's time step number (`ITEM: TIMESTEP`).
std::vector<std::vector<double>> read_dump_rows(const std::string& path, int columns,
                                                long* timestep);

/// The programs a LIGGGHTS run on np ranks needs, found on the PATH (mpirun only for np > 1).
struct LiggghtsPrograms {
  std::string liggghts, mpirun;
};
/// Finds them; InputError when liggghts (or, for np > 1, mpirun) is not installed.
LiggghtsPrograms require_liggghts(int np);

/// Runs `liggghts -in in.rig` in `dir` (under `mpirun -np np` for np > 1), passing every line
/// the deck prints as "clumpkit: ..." to `say`; the whole screen output goes to dir/screen.txt.
/// Throws InputError when liggghts (or mpirun) is not installed, NumericalError with
/// LIGGGHTS's ERROR line when the run fails.
void run_liggghts(const std::string& dir, int np,
                  const std::function<void(const std::string&)>& say);

}  // namespace clumpkit::rigs::detail
