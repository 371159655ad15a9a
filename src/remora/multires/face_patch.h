// A patch of a triangle mesh's faces: a flag per face (`in`) and their list (`faces`), grown by
// rings, closed into a manifold part with a clean border, and cut out as a mesh of its own. The
// local bake's patch (bake.h) and the coarse base of the nonlinear preview (nonlinear_region.h)
// are made with it.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "remora/mesh/mesh.h"
#include "remora/multires/phong.h"

namespace remora {

/// Adds every face around vertex `v` of `t` to the patch.
void add_fan(const TriangleTopology& t, int v, std::vector<char>& in, std::vector<int>& faces);
/// Grows the patch by `rings` rings: every face around a vertex of a patch face.
void grow_rings(const TriangleTopology& t, int rings, std::vector<char>& in,
                std::vector<int>& faces);
/// Makes the patch a manifold part with a clean border: a vertex where two runs of patch faces
/// meet takes all its faces; with `bridges`, so do both faces of an edge outside the patch
/// between two patch vertices (its ends would be joined twice once the patch is remeshed).
/// `mesh` is the mesh `t` was read from.
void close_patch(const Mesh& mesh, const TriangleTopology& t, bool bridges, std::vector<char>& in,
                 std::vector<int>& faces);
/// The faces `faces` of `t` as a mesh of their own, at `points` (a row per vertex of `t`): its
/// vertices in the order they first appear (`vertices`: patch vertex -> vertex of `t`; `local`,
/// sized to t's vertices and -1 where unset: vertex of `t` -> patch vertex), the faces in their
/// order and corner order. Throws what build_mesh() throws for a part that is not manifold.
Mesh sub_mesh(const TriangleTopology& t, const Eigen::MatrixXd& points,
              const std::vector<int>& faces, std::vector<int>& local, std::vector<int>& vertices);

} // namespace remora
