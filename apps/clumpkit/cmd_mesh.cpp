// clumpkit mesh SHAPE -o FILE.stl|obj [--triangles N] [--seed S] [--units m|mm]: writes one of the
// bundled test shapes (issue 4) as a closed, outward-oriented triangle mesh. --list names them.
#include <fmt/format.h>

#include <iostream>

#include "cli_util.hpp"
#include "clumpkit/core/atomic_file.hpp"
#include "clumpkit/core/error.hpp"
#include "clumpkit/core/units.hpp"
#include "clumpkit/fill/shape_library.hpp"

namespace clumpkit::cli {
namespace {

struct MeshArgs {
  std::string shape, out, units = "m";
  int triangles = 2000;
  std::uint64_t seed = 1;
  bool list = false;
};

Command setup_mesh(CLI::App& parent) {
  auto a = std::make_shared<MeshArgs>();
  CLI::App* c = parent.add_subcommand(
      "mesh",
      "Write a bundled test shape (pills, ellipsoid, capsule, cube, seed, rock, torus, "
      "bracket) as a closed triangle mesh (ASCII STL or OBJ)");
  c->add_option("SHAPE", a->shape, "Test shape name (see --list)");
  c->add_flag("--list", a->list, "List the test shapes with their dimensions");
  c->add_option("-o,--output", a->out, "Output mesh: .stl (ASCII) or .obj");
  c->add_option("--triangles", a->triangles,
                "Approximate triangle count of curved shapes (flat-faced ones keep their faces)")
      ->check(CLI::Range(16, 2'000'000));
  c->add_option("--seed", a->seed, "Seed of the random shapes (rock)");
  c->add_option("--units", a->units, "Length unit of the written coordinates (m, mm, ...)");
  return {c, [a] {
            if (a->list) {
              for (const std::string& n : test_shape_names())
                std::cout << fmt::format("{:<18} {}\n", n, test_shape_description(n));
              return 0;
            }
            if (a->shape.empty()) throw InputError("", "SHAPE", "name a shape (see --list)");
            if (a->out.empty()) throw InputError("", "--output", "required (FILE.stl or FILE.obj)");
            const std::string ext = std::filesystem::path(a->out).extension().string();
            if (ext != ".stl" && ext != ".obj")
              throw InputError(a->out, "--output", "must end in .stl or .obj");
            const double scale = 1.0 / unit_factor(a->units, Dimension::Length, "", "--units");
            check_writable(a->out, "--output");
            const auto solid = make_test_shape(a->shape, a->seed);
            const TessellatedMesh mesh = solid->tessellate(a->triangles);
            const std::string title = fmt::format("{} units={}", a->shape, a->units);
            write_file_atomic(a->out, ext == ".stl" ? to_ascii_stl(mesh, title, scale)
                                                    : to_obj(mesh, title, scale));
            std::cout << fmt::format(
                "{}: {} triangles, {} vertices, mesh volume {:.4g} mm^3 (exact shape {:.4g} "
                "mm^3) -> {}\n",
                a->shape, mesh.triangles.size(), mesh.vertices.size(), mesh.signed_volume() * 1e9,
                solid->volume() * 1e9, a->out);
            return 0;
          }};
}

const Registration reg_mesh(15, setup_mesh);

}  // namespace
}  // namespace clumpkit::cli
