#include "clumpkit/dem/profile.hpp"

#include <cstdio>

namespace clumpkit::dem {

std::string Profile::table() const {
  const double tot = total();
  std::string s = "stage         time (s)   share\n";
  auto row = [&](const char* name, double t) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%-12s %9.3f  %5.1f %%\n", name, t,
                  tot > 0.0 ? 100.0 * t / tot : 0.0);
    s += buf;
  };
  row("neighbours", neighbours);
  row("contacts", contacts);
  row("forces", forces);
  row("integrate", integrate);
  row("walls", walls);
  row("insert", insert);
  row("checks", checks);
  row("output", output);
  row("total", tot);
  char buf[96];
  std::snprintf(buf, sizeof buf, "steps %ld, neighbour rebuilds %ld (%ld spared)\n", steps,
                neighbour_rebuilds, neighbour_rebuilds_spared);
  s += buf;
  if (implicit_clump_steps > 0) {
    std::snprintf(
        buf, sizeof buf, "implicit damping: %.3g %% of %ld clump-steps\n",
        100.0 * static_cast<double>(implicit_clump_steps) / static_cast<double>(clump_steps),
        clump_steps);
    s += buf;
  }
  return s;
}

}  // namespace clumpkit::dem
