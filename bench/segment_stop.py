#!/usr/bin/env python3
"""Adds a benchmark stop to a copy of lib/src/dem/step.cpp (bench/segment_bench.sh uses it on a
temporary worktree; the repository's engine has no such hook). With CLUMPKIT_SEGMENT_STEPS=N in
the environment, World::step prints, after its N-th step, the stage times so far and the state
hash, then times each stage 300 more times on that state (not with CLUMPKIT_SEGMENT_NO_TIMING set:
bench/callgrind_segment.sh counts the steps alone) and exits. With
CLUMPKIT_SEGMENT_SKIN=F the default Verlet skin is F times the smallest sphere radius instead of
0.3 (lib/src/dem/world.cpp, patched beside step.cpp): the lists change, the results do not."""
import os
import sys

path = sys.argv[1]
world = os.path.join(os.path.dirname(path), "world.cpp")
wsrc = open(world).read()
skin = "w.skin = s.skin > 0.0 ? s.skin : 0.3 * w.r_min;"
if wsrc.count(skin) != 1:
    sys.exit(f"{world}: the default skin was not found; update bench/segment_stop.py")
wsrc = "#include <cstdlib>\n" + wsrc.replace(skin, (
    'w.skin = s.skin > 0.0 ? s.skin : (std::getenv("CLUMPKIT_SEGMENT_SKIN") ? '
    'std::atof(std::getenv("CLUMPKIT_SEGMENT_SKIN")) : 0.3) * w.r_min;'))
open(world, "w").write(wsrc)
src = open(path).read()
anchor = "  ++w.profile.steps;\n}"
if src.count(anchor) != 1:
    sys.exit(f"{path}: the end of World::step was not found; update bench/segment_stop.py")
stop = r'''  ++w.profile.steps;
  static const long stop_at = std::getenv("CLUMPKIT_SEGMENT_STEPS")
                                  ? std::atol(std::getenv("CLUMPKIT_SEGMENT_STEPS")) : 0;
  if (stop_at > 0 && w.profile.steps == stop_at) {
    const Profile& p = w.profile;
    long wall_n = 0;
    for (int s : w.wall_active) wall_n += w.wall_contact_n[s];
    std::fprintf(stderr,
                 "SEGMENT %ld steps: total %.3f s, neighbours %.3f, contacts %.3f, forces %.3f, "
                 "integrate %.3f; %ld rebuilds; state hash %016llx\n"
                 "  %zu spheres, %zu listed pairs, %zu pair contacts, %zu spheres near a wall, "
                 "%ld wall contacts\n",
                 p.steps, p.total(), p.neighbours, p.contacts, p.forces, p.integrate,
                 p.neighbour_rebuilds, static_cast<unsigned long long>(state_hash()),
                 w.s_r.size(), w.pairs.size(), w.pair_contacts.size(), w.wall_active.size(),
                 wall_n);
    auto timeit = [&](const char* name, auto&& fn) {
      std::vector<double> v;
      for (int r = 0; r < 300; ++r) {
        const auto a = Clock::now();
        fn();
        v.push_back(std::chrono::duration<double>(Clock::now() - a).count() * 1e6);
      }
      std::sort(v.begin(), v.end());
      std::fprintf(stderr, "  %-18s min %8.1f us, quartile %8.1f us, median %8.1f us\n", name,
                   v[0], v[75], v[150]);
    };
    if (!std::getenv("CLUMPKIT_SEGMENT_NO_TIMING")) {
      timeit("detect_contacts", [&] { w.detect_contacts(); });
      timeit("compute_forces", [&] { w.compute_forces(w.dt); });
      timeit("kick_and_drift", [&] { w.kick_and_drift(); });
      timeit("rebuild_neighbours", [&] { w.rebuild_neighbours(); });
    }
    std::fflush(stderr);
    std::_Exit(0);
  }
}'''
src = "#include <cstdlib>\n" + src.replace(anchor, stop)
open(path, "w").write(src)
