// The steps of the local bake (bake.h), internal to src/remora/multires/:
//   bake.cpp        the order of the steps, the filter's band, the base's moved vertices, the
//                   fallback to the full preprocess
//   bake_patch.cpp  the patch to remesh again and the part of S' under it, as meshes
//   bake_stitch.cpp the remeshed patch stitched into the base, the correspondences mended, the
//                   base's figures
#pragma once

#include <vector>

#include <Eigen/Core>

#include "remora/common/error.h"
#include "remora/mesh/splice.h"
#include "remora/multires/bake.h"
#include "remora/remesh/remesh.h"

namespace remora::bake_detail {

/// Where the local bake cannot go on; bake() then preprocesses in full, with this message as the
/// reason.
class NotLocal : public Error {
public:
  using Error::Error;
};

/// What the steps share: the old editor's pieces and the new ones as they are made. Vertex and
/// face indices are the old editor's.
struct Bake {
  EditorPartsView old;
  const EditorOptions& options;
  const BakeOptions& settings;
  BakeReport& report;
  Eigen::MatrixXd input_positions; ///< O'
  std::vector<char> in_band;       ///< per input vertex: S' may differ from S
  Eigen::MatrixXd smooth;          ///< S'
  Eigen::MatrixXd base_points;     ///< B': the base with the vertices on S' moved
  std::vector<char> moved;         ///< per base vertex: it went with S'
  std::vector<char> patch;         ///< per base face: remeshed again
};

/// The patch and the part of S' under it as meshes of their own, with the maps back.
struct PatchMeshes {
  RemeshPatch patch;                   ///< mesh: B' on the patch faces, in their order
  Mesh reference;                      ///< S' on the input faces under the patch and a margin
  std::vector<int> patch_vertices;     ///< patch vertex -> base vertex
  std::vector<int> reference_vertices; ///< reference vertex -> input vertex
  std::vector<int> reference_faces;    ///< reference face -> input face
};

/// Marks the patch: the faces around base edges whose length changed by more than
/// settings.distortion, grown by settings.rings rings and made manifold. False when no edge
/// changed. Throws NotLocal when the patch holds more than max_fraction of the faces.
bool select_patch(Bake& b);
/// The patch and its reference as meshes (bake_patch.cpp). Throws NotLocal when a part of the
/// patch has no border.
PatchMeshes patch_meshes(const Bake& b);
/// The new editor's base into `parts` (an empty EditorParts): `remeshed` spliced in place of the
/// patch (`map` says where its elements went), or B' alone when there is none (`meshes` and
/// `remeshed` null); with its correspondence to the input. The other parts are left to
/// carry_input() and mend().
void stitch(const Bake& b, const PatchMeshes* meshes, const RemeshPatchResult* remeshed,
            SpliceMap& map, EditorParts& parts);
/// The new editor's input, its topology and filter: the old ones, with O' in the band. Touches no
/// part that stitch() or mend() writes.
void carry_input(const Bake& b, EditorParts& parts);
/// The new editor's input on the base (each input vertex located again where the base or S' moved
/// under it), O', S' (both moved out of b: call it after carry_input()), the base's topology and
/// rest positions. Throws NotLocal
/// when the correspondence cannot be carried over. `map` is null without a patch.
void mend(Bake& b, const PatchMeshes* meshes, const RemeshPatchResult* remeshed,
          const SpliceMap* map, EditorParts& parts);
/// What the bake changed in the base (base_figures.h): the patch's faces, old and new, and the
/// kept faces with a moved corner (`map` as stitch() made it; null without a patch).
BaseChange base_change(const Bake& b, const SpliceMap* map);
/// The new base's figures into parts.report and its negative cotan edges, updated where the
/// base changed, all but those over the vertex statistics (update_vertex_figures()).
void base_figures(const Bake& b, const BaseChange& change, EditorParts& parts,
                  const SpliceMap* map);

} // namespace remora::bake_detail
