// LIGGGHTS 3.8: a spheres file ("x y z r" per line, what `spheres file F` reads) and a deck
// snippet with `fix particletemplate/multisphere`. With `mass ... inertia_tensor ... use_density`
// LIGGGHTS takes the union's mass and tensor as given and places the centre of mass at the
// template origin (fix_template_multisphere.cpp: "using xcm = 0/0/0"), which is why the
// template must be in its centroid frame.
#include <fmt/format.h>

#include <cctype>

#include "format_text.hpp"

namespace clumpkit::export_detail {

namespace {

// The template's seed: LIGGGHTS wants a prime above 10000, and refuses an insertion whose
// templates, distribution and insertion share a seed, so each template type gets its own:
// the type-th prime from 15485863 on.
unsigned long template_seed(int type) {
  auto prime = [](unsigned long n) {
    for (unsigned long d = 2; d * d <= n; ++d)
      if (n % d == 0) return false;
    return true;
  };
  unsigned long p = 15485863;
  for (int k = 1; k < type; ++k) do
      ++p;
    while (!prime(p));
  return p;
}

}  // namespace

std::vector<ExportFile> render_liggghts(const ClumpTemplate& c, const ExportSettings& s) {
  require_principal_frame(c, "liggghts");
  const std::string base = export_base_name(c, s);
  const std::string spheres_name = base + "_spheres.txt";
  std::string spheres;
  for (const Sphere& sp : c.spheres)
    spheres += fmt::format("{} {} {} {}\n", num(sp.center[0]), num(sp.center[1]), num(sp.center[2]),
                           num(sp.radius));

  std::string id;  // LIGGGHTS fix IDs: letters, digits, underscores
  for (char ch : base) id += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
  const Eigen::Matrix3d I = principal_inertia(c);
  std::string snip = provenance_block(c, "liggghts", "# ");
  snip += "#\n";
  snip += "# Insert with: fix particledistribution/discrete SEED 1 pts_" + id + " 1.0,\n" +
          "# then fix insert/pack (or insert/stream) with distributiontemplate, and exactly one\n"
          "# 'fix ... multisphere'. The spheres file path is relative to the working folder of\n"
          "# liggghts. Seeds must be primes above 10000, all different within an insertion\n"
          "# (this template's seed is the type-th prime from 15485863 on: export each template\n"
          "# with its own --type).\n";
  snip +=
      "# Template frame: positions are relative to the union's centre of mass, along its\n"
      "# principal axes; inertia_tensor (Ixx Ixy Ixz Iyy Iyz Izz, kg m^2, about the centre of\n"
      "# mass) is therefore diag(principal moments).\n";
  snip += fmt::format(
      "fix pts_{id} all particletemplate/multisphere {seed} atom_type {atom} density constant "
      "{rho} nspheres {n} ntry 1000000 spheres file {file} scale 1.0 type {type} mass {m} "
      "inertia_tensor {ixx} {ixy} {ixz} {iyy} {iyz} {izz} use_density\n",
      fmt::arg("id", id), fmt::arg("seed", template_seed(s.template_type)),
      fmt::arg("atom", s.atom_type), fmt::arg("rho", num(c.mass.density)),
      fmt::arg("n", c.spheres.size()), fmt::arg("file", spheres_name),
      fmt::arg("type", s.template_type), fmt::arg("m", num(c.mass.mass)),
      fmt::arg("ixx", num(I(0, 0))), fmt::arg("ixy", num(I(0, 1))), fmt::arg("ixz", num(I(0, 2))),
      fmt::arg("iyy", num(I(1, 1))), fmt::arg("iyz", num(I(1, 2))), fmt::arg("izz", num(I(2, 2))));
  return {{spheres_name, spheres}, {base + ".liggghts", snip}};
}

}  // namespace clumpkit::export_detail
