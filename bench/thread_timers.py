#!/usr/bin/env python3
"""Adds per-thread timers to a copy of lib/src/dem/step.cpp that bench/segment_stop.py has already
patched (bench/segment_bench.sh runs both with THREAD_TIMERS=1; the repository's engine has no
such timers). Each thread adds up, with omp_get_wtime, the time it spends in each part of
detect_contacts' pair scan and of compute_forces' parallel region, waits at the barriers that
end a part included; the segment stop prints the sums per thread after its SEGMENT line:

  pair scan      the listed pairs' distance test (detect_contacts)
  pair geometry  writing the touching pairs' contact geometry (detect_contacts)
  kinematics     each clump's angular velocity and predicted velocity (compute_forces)
  index          the per-clump contact index, in four parts with its barrier and single
  pair laws      the pair contacts' laws
  wall laws      the wall contacts' laws, with the barrier that ends them
  sums           each clump's force and torque, and its implicit damping

What it shows: whether two threads each do their half of a part in half the time one thread
takes for all of it (session 27 found each thread taking as long as one thread alone: docs/dem.md).
The anchors below are text of step.cpp; if one is missing the script stops and names it."""
import sys

path = sys.argv[1]
src = open(path).read()


def rep(old, new):
    global src
    if src.count(old) != 1:
        sys.exit(f"{path}: anchor not found once, update bench/thread_timers.py:\n{old}")
    src = src.replace(old, new)


def rep_either(pairs):
    """The first (old, new) whose anchor is there: the code as it is (first), or with
    bench/tried/range_cursors.diff applied (its threads also take what is left of the
    other's laws and sums, so those parts include that work)."""
    for old, new in pairs:
        if src.count(old) == 1:
            return rep(old, new)
    rep(pairs[0][0], pairs[0][1])  # stops, naming the current code's anchor


PARTS = ["kinematics", "index (count)", "index (barrier)", "index (single)", "index (list)",
         "pair laws", "wall laws", "sums", "", "", "pair scan", "pair scan (barrier)",
         "pair geometry"]
rep("namespace clumpkit::dem {\n",
    "namespace clumpkit::dem {\n"
    "alignas(64) double g_thread_timer[2][16][8];  // [thread][part], one cache line each\n"
    "#define THREAD_TIMER(i) do { const double n_ = omp_get_wtime(); "
    "const int t_ = omp_get_thread_num(); "
    "if (t_ < 2) g_thread_timer[t_][i][0] += n_ - last_; last_ = n_; } while (0)\n")
# compute_forces
rep("    const int nt = omp_get_num_threads(), t = omp_get_thread_num();\n",
    "    const int nt = omp_get_num_threads(), t = omp_get_thread_num();\n"
    "    double last_ = omp_get_wtime();\n")
rep("    std::vector<int>& count = j_count[t];",
    "    THREAD_TIMER(0);\n    std::vector<int>& count = j_count[t];")
rep("#pragma omp barrier\n#pragma omp single\n    {\n      int at = 0;",
    "    THREAD_TIMER(1);\n#pragma omp barrier\n    THREAD_TIMER(2);\n"
    "#pragma omp single\n    {\n      int at = 0;")
rep("    for (int k = k0; k < k1; ++k) j_list[count[clump_j(k)]++] = k;\n",
    "    THREAD_TIMER(3);\n    for (int k = k0; k < k1; ++k) j_list[count[clump_j(k)]++] = k;\n"
    "    THREAD_TIMER(4);\n")
# With bench/tried/range_cursors.diff the laws and sums are lambdas run by RangeCursors.
rep_either([("      block_energy[b] = block_elastic;\n    }\n",
             "      block_energy[b] = block_elastic;\n    }\n    THREAD_TIMER(5);\n"),
            ("      block_energy[b] = block_elastic;\n    });\n",
             "      block_energy[b] = block_elastic;\n    });\n    THREAD_TIMER(5);\n")])
rep_either([("    // Sums (the loop above ends in a barrier",
             "    THREAD_TIMER(6);\n    // Sums (the loop above ends in a barrier"),
            ("#pragma omp barrier\n    sum_cursors.run(",
             "#pragma omp barrier\n    THREAD_TIMER(6);\n    sum_cursors.run(")])
rep_either([("        if (hdt > 0.0 && damp_implicitly(c)) ++n_implicit;\n      }\n    }",
             "        if (hdt > 0.0 && damp_implicitly(c)) ++n_implicit;\n      }\n    }\n"
             "    THREAD_TIMER(7);"),
            ("          if (hdt > 0.0 && damp_implicitly(c)) ++n_implicit;\n        }\n      }\n    });",
             "          if (hdt > 0.0 && damp_implicitly(c)) ++n_implicit;\n        }\n      }\n"
             "    });\n    THREAD_TIMER(7);")])
# detect_contacts
rep("    const int t = omp_get_thread_num();\n"
    "    const int k0 = static_cast<int>(std::int64_t(np) * t / nt);",
    "    const int t = omp_get_thread_num();\n    double last_ = omp_get_wtime();\n"
    "    const int k0 = static_cast<int>(std::int64_t(np) * t / nt);")
rep("#pragma omp barrier\n#pragma omp single\n    {\n      for (int u = 0; u < nt; ++u) offset",
    "    THREAD_TIMER(10);\n#pragma omp barrier\n    THREAD_TIMER(11);\n#pragma omp single\n"
    "    {\n      for (int u = 0; u < nt; ++u) offset")
rep("    scratch_max[t] = {best, best_k};\n  }",
    "    scratch_max[t] = {best, best_k};\n    THREAD_TIMER(12);\n  }")
# The report, after the segment stop's SEGMENT lines.
names = "".join(f'"{n}", ' for n in PARTS)
rep("    auto timeit = ",
    "    {\n"
    f"      const char* parts[] = {{{names}}};\n"
    "      for (int i = 0; i < 13; ++i)\n"
    "        if (parts[i][0])\n"
    '          std::fprintf(stderr, "  per thread: %-20s %8.3f s %8.3f s\\n", parts[i],\n'
    "                       g_thread_timer[0][i][0], g_thread_timer[1][i][0]);\n"
    "    }\n"
    "    auto timeit = ")
open(path, "w").write(src)
