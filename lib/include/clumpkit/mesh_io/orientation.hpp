#pragma once
/// Orientation of a closed triangle mesh, body by body: which bodies (connected components) face
/// the wrong way, and the repair of a closed, manifold mesh whose faces disagree on orientation
/// (common in STL files from scanners and some CAD exports).
///
/// Outward means: a body that lies inside an even number of the mesh's other bodies (a solid, or
/// an island inside a cavity) encloses positive volume; one inside an odd number (a cavity's
/// wall) encloses negative volume. Nesting is decided by the generalised winding number of a
/// point of the body with respect to every other body whose bounding box holds that point.
#include <cstddef>
#include <string>

#include "clumpkit/mesh_io/triangle_mesh.hpp"

namespace clumpkit {

struct BodyOrientation {
  std::size_t bodies = 0;       ///< vertex-connected components with at least one triangle
  std::size_t misoriented = 0;  ///< fewest bodies to turn so that all face by their nesting
  std::size_t solids = 0;       ///< bodies inside no other: separate pieces (a cavity is not one)
};

/// Counts the bodies of a mesh whose every edge is shared by two consistently oriented triangles,
/// and how many of them face against their nesting, the whole mesh's orientation being free (a
/// mesh inside out as a whole is flipped by load_mesh): the fewer of those facing one way and
/// those facing the other. A mesh of one body is never misoriented.
BodyOrientation body_orientation(const TriangleMesh& mesh);

/// Re-orients a closed, manifold mesh (every edge shared by exactly two triangles; indices valid)
/// so that neighbouring triangles agree and every body faces outward by its nesting. Returns the
/// number of triangles reversed. Throws InputError(where, "", ...) when an edge is not shared by
/// exactly two triangles or a body is not orientable (a Möbius-like surface), with the counts.
std::size_t orient_outward(TriangleMesh& mesh, const std::string& where);

/// Makes neighbouring triangles agree on orientation on a manifold mesh that may be open (edges
/// of one triangle allowed), each body's orientation taken from its first triangle. Returns the
/// number of triangles reversed. Throws InputError as orient_outward for an edge of more than two
/// triangles or a one-sided surface.
std::size_t orient_consistently(TriangleMesh& mesh, const std::string& where);

}  // namespace clumpkit
