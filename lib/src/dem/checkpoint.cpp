// Checkpoints: the complete dynamic state in a binary file (written atomically), so that a
// resumed run continues bit-identically.
#include <cstring>
#include <sstream>

#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "dem/world_impl.hpp"

namespace clumpkit::dem {

namespace {

constexpr char kMagic[] = "clumpkit-dem-checkpoint/2";  // 2: ContactHistory.damping

struct Writer {
  std::string buf;
  void bytes(const void* p, size_t n) { buf.append(static_cast<const char*>(p), n); }
  template <class T>
  void value(const T& v) {
    bytes(&v, sizeof v);
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    value<std::uint64_t>(v.size());
    if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
  }
  void str(const std::string& s) {
    value<std::uint64_t>(s.size());
    bytes(s.data(), s.size());
  }
};

struct Reader {
  const std::string& buf;
  size_t at = 0;
  std::string where;
  void bytes(void* p, size_t n) {
    if (at + n > buf.size()) throw InputError(where, "", "checkpoint is truncated");
    std::memcpy(p, buf.data() + at, n);
    at += n;
  }
  template <class T>
  void value(T& v) {
    bytes(&v, sizeof v);
  }
  template <class T>
  void vec(std::vector<T>& v) {
    std::uint64_t n = 0;
    value(n);
    if (n > buf.size()) throw InputError(where, "", "checkpoint is corrupt");
    v.resize(n);
    if (n) bytes(v.data(), n * sizeof(T));
  }
  void str(std::string& s) {
    std::uint64_t n = 0;
    value(n);
    if (n > buf.size()) throw InputError(where, "", "checkpoint is corrupt");
    s.resize(n);
    if (n) bytes(s.data(), n);
  }
};

}  // namespace

void World::save_checkpoint(const std::filesystem::path& path) const {
  const Impl& w = *impl_;
  Writer o;
  o.bytes(kMagic, sizeof kMagic);
  o.value(w.fingerprint);
  o.value(w.time);
  o.value(w.steps);
  o.vec(w.c_type);
  o.vec(w.c_x);
  o.vec(w.c_v);
  o.vec(w.c_wb);
  o.vec(w.c_q);
  o.vec(w.c_f);
  o.vec(w.c_t);
  o.vec(w.c_mroll);
  o.vec(w.s_pos_build);
  o.vec(w.pairs);
  o.vec(w.pair_hist);
  o.vec(w.wall_cand_start);
  o.vec(w.wall_cand);
  o.vec(w.wall_slots);
  o.value(w.need_rebuild);
  o.value(w.forces_valid);
  o.value(w.elastic);
  for (const WallData& wd : w.walls) {
    o.vec(wd.vertices_build);
    o.value(wd.state.force);
    o.value(wd.state.torque);
  }
  for (const FactoryRuntime& f : w.factories) {
    o.vec(f.type_mass);
    o.value(f.status);
    o.value(f.batch);
    o.value(f.interval);
    std::ostringstream rng;
    rng << f.rng;
    o.str(rng.str());
  }
  o.value(w.check_energy);
  o.value(w.check_ke);
  o.value(w.check_elastic);
  o.value(w.wall_work);
  o.value(w.inserted_energy);
  o.value(w.check_initialised);
  // Trailer: the walls' motions (World::set_wall_motion may have changed them after creation).
  // Checkpoints written before the trailer existed load with the motions of the settings.
  o.str("wall-motions");
  for (const WallData& wd : w.walls) {
    o.vec(wd.motion.translation.times);
    o.vec(wd.motion.translation.velocities);
    o.value(static_cast<std::uint8_t>(wd.motion.rotation ? 1 : 0));
    if (wd.motion.rotation) o.value(*wd.motion.rotation);
  }
  // Second trailer: the pinch-release tally (older checkpoints load with none).
  o.str("pinched");
  o.value(w.pinched_count);
  o.value(w.pinched_mass);
  write_file_atomic(path, o.buf);
}

void World::load_checkpoint(const std::filesystem::path& path) {
  const std::string data = read_file(path);
  Reader in{data, 0, path.string()};
  char magic[sizeof kMagic];
  in.bytes(magic, sizeof magic);
  if (std::memcmp(magic, kMagic, sizeof kMagic) != 0)
    throw InputError(path.string(), "", "not a clumpkit DEM checkpoint");
  Impl& w = *impl_;
  std::uint64_t fp = 0;
  in.value(fp);
  if (fp != w.fingerprint)
    throw InputError(path.string(), "",
                     "the checkpoint was written by a simulation with other settings (clump "
                     "types, walls, time step, factories or seed differ)");
  in.value(w.time);
  in.value(w.steps);
  std::vector<int> types;
  in.vec(types);
  // Rebuild the sphere arrays from the clumps, then overwrite the dynamic state.
  w.c_type.clear();
  w.c_first.clear();
  w.c_x.clear();
  w.c_v.clear();
  w.c_q.clear();
  w.c_R.clear();
  w.c_wb.clear();
  w.c_f.clear();
  w.c_t.clear();
  w.c_mroll.clear();
  w.s_clump.clear();
  w.s_r.clear();
  w.s_off.clear();
  w.s_pos.clear();
  w.s_pos_build.clear();
  w.wall_slots.clear();
  w.wall_held.clear();
  w.wall_contacts.clear();
  w.wall_row.clear();
  w.wall_contact_n.clear();
  w.wall_cand_start.assign(1, 0);
  for (int t : types) {
    if (t < 0 || t >= static_cast<int>(w.types.size()))
      throw InputError(path.string(), "", "checkpoint is corrupt (clump type)");
    w.add_clump(t, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero(),
                Eigen::Vector3d::Zero());
  }
  in.vec(w.c_x);
  in.vec(w.c_v);
  in.vec(w.c_wb);
  in.vec(w.c_q);
  in.vec(w.c_f);
  in.vec(w.c_t);
  in.vec(w.c_mroll);
  in.vec(w.s_pos_build);
  in.vec(w.pairs);
  in.vec(w.pair_hist);
  w.pair_live.clear();  // rebuilt from the histories at the next detection
  // The bins of the last rebuild are not in the checkpoint: none until the next rebuild (the
  // search before a rebuild then tests the moved clumps directly or rebuilds).
  w.scratch_bins.clear();
  in.vec(w.wall_cand_start);
  in.vec(w.wall_cand);
  in.vec(w.wall_slots);
  w.recount_wall_held();
  in.value(w.need_rebuild);
  w.wall_active_dirty = true;
  in.value(w.forces_valid);
  in.value(w.elastic);
  const size_t nc = types.size();
  if (w.c_x.size() != nc || w.c_v.size() != nc || w.c_q.size() != nc ||
      w.s_pos_build.size() != w.s_r.size() || w.wall_slots.size() != w.s_r.size() ||
      w.wall_cand_start.size() != w.s_r.size() + 1 || w.pair_hist.size() != w.pairs.size())
    throw InputError(path.string(), "", "checkpoint is corrupt (array sizes)");
  for (size_t c = 0; c < nc; ++c) w.c_R[c] = w.c_q[c].toRotationMatrix();
  w.update_spheres(0);
  w.move_walls();
  for (WallData& wd : w.walls) {
    in.vec(wd.vertices_build);
    in.value(wd.state.force);
    in.value(wd.state.torque);
  }
  for (FactoryRuntime& f : w.factories) {
    in.vec(f.type_mass);
    in.value(f.status);
    in.value(f.batch);
    in.value(f.interval);
    std::string rng;
    in.str(rng);
    std::istringstream is(rng);
    is >> f.rng;
  }
  in.value(w.check_energy);
  in.value(w.check_ke);
  in.value(w.check_elastic);
  in.value(w.wall_work);
  in.value(w.inserted_energy);
  in.value(w.check_initialised);
  if (in.at < data.size()) {
    std::string tag;
    in.str(tag);
    if (tag != "wall-motions")
      throw InputError(path.string(), "", "checkpoint is corrupt (trailer)");
    for (WallData& wd : w.walls) {
      WallMotion m;
      in.vec(m.translation.times);
      in.vec(m.translation.velocities);
      std::uint8_t rot = 0;
      in.value(rot);
      if (rot) {
        WallRotation r;
        in.value(r);
        m.rotation = r;
      }
      wd.motion = m;
    }
    for (size_t k = 0; k < w.walls.size(); ++k) w.settings.walls[k].motion = w.walls[k].motion;
    w.move_walls();
  }
  if (in.at < data.size()) {
    std::string tag;
    in.str(tag);
    if (tag != "pinched") throw InputError(path.string(), "", "checkpoint is corrupt (trailer)");
    in.value(w.pinched_count);
    in.value(w.pinched_mass);
    if (w.pinched_count < 0 || !(w.pinched_mass >= 0.0))
      throw InputError(path.string(), "", "checkpoint is corrupt (pinched)");
  }
  if (in.at != data.size())
    throw InputError(path.string(), "", "checkpoint is corrupt (trailing bytes)");
  // The contacts of the saved step are re-detected (detection is a pure function of positions
  // and histories are already restored): nothing else needs them before the next force pass.
  w.pair_contacts.clear();
  w.pair_contact_clumps.clear();
}

}  // namespace clumpkit::dem
