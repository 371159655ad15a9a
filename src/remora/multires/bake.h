// The local bake: after an edit, the edited shape O' becomes the input of a new editor, and only
// what the edit changed is preprocessed again (docs/editing.md, "Baking an edit").
//
//   1. Filter: the low-pass filter is linear, S' = F(O') = S + F(O' − O), and O' − O vanishes
//      outside the vertices the edit moved. F(O' − O) is solved on those vertices and a band of
//      `margin` σ around them (LowPassFilter::apply_local); S' = S bit for bit outside. F keeps
//      the metric of the input the first editor was built from (a full preprocess filters with
//      O''s): the difference is of the size of what two equally good bases of one shape differ.
//   2. Base: a base vertex located (base_on_input) on a face that S' moves goes with it,
//      B'_v = S' at its location; every other base vertex keeps its point bit for bit.
//   3. Patch: where a base edge's length changed by more than `distortion`, its faces and
//      `rings` rings around them are remeshed again with the base's own l and mean area, their
//      border locked, on the part of S' under them (remesh_patch(), remesh/remesh.h), and
//      spliced back (mesh/splice.h). Both correspondences are carried over and mended where the
//      base moved; the report's base figures are updated where the base changed.
//   4. The new editor adopts O', S', the filter (O's, shared: the metric stays the one the
//      editor was built with), the base and the correspondences, built in place
//      (Editor(build, options)), and the old editor's Laplacian assembler (linalg/kharmonic.h)
//      and base normals updated where the base changed.
//
// Where the local bake cannot work (no remeshed base, feature lines, a band or patch covering
// most of the mesh, a patch without border, a failure on the way), bake() preprocesses O' in
// full instead and says why in the report.
#pragma once

#include <cstddef>
#include <map>
#include <string>

#include "remora/multires/editor.h"

namespace remora {

struct BakeOptions {
  /// Width of the filter's band around the moved input vertices, in σ. The filter's kernel
  /// decays like exp(−d/σ), so the band's truncation error falls by about e per σ of width
  /// (measured against the whole mesh's filter: docs/editing.md, "Baking an edit").
  double margin = 6.0;
  /// A base edge whose length changed by more than this fraction makes its faces part of the
  /// patch that is remeshed again.
  double distortion = 0.05;
  int rings = 2; ///< rings of base faces added around the distorted ones
  /// The patch's remesh: cycles (then more while they still change it, as RemeshOptions says)
  /// and fine-tuning iterations. It starts from a remesh only stretched a little, and needs
  /// fewer than a remesh of the raw input (docs/editing.md has what fewer cost and saved).
  int cycles = 4;
  int equalize_iterations = 6;
  /// The full preprocess runs instead when the band holds more than this share of the input's
  /// vertices, or the patch more than this share of the base's faces.
  double max_fraction = 0.5;
  bool force_full = false; ///< always the full preprocess (for comparisons)
};

struct BakeReport {
  bool local = false;
  std::string fallback;                    ///< why the full preprocess ran (empty when local)
  std::size_t changed_vertices = 0;        ///< input vertices the edit moved
  std::size_t band_vertices = 0;           ///< input vertices the filter solved on
  std::size_t moved_base_vertices = 0;     ///< base vertices that went with S'
  std::size_t patch_faces = 0;             ///< base faces remeshed again
  std::size_t patch_faces_after = 0;       ///< the faces that replaced them
  std::size_t reference_faces = 0;         ///< faces of S' under the patch
  std::size_t rewalked_input_vertices = 0; ///< input vertices located on the new base by a walk
  /// Wall time: "filter", "base", "patch" (selection and sub-meshes), "remesh", "stitch" (the
  /// splice), then on one thread "mend" (the input copied and located on the new base), "report"
  /// (the base's figures), "normals" (the base's normals, updated where it changed) and "wait"
  /// (for the second thread), while the second builds the "assembler" (the old editor's
  /// Laplacian assembler updated where the base changed, then the figures over the vertex
  /// statistics; with threads = 1 it runs inside "wait"); "editor" (the new editor's checks
  /// after its parts are built in place), "total"; only "total" for the full preprocess.
  std::map<std::string, double> milliseconds;
  /// The process's CPU time (all threads) in the same parts: on a busy machine the wall time
  /// says little about a part's own work.
  std::map<std::string, double> cpu_milliseconds;
};

struct BakeResult {
  Editor editor;
  BakeReport report;
};

/// Bakes the editor's current result (positions(): the edit under the current transforms) into
/// a new editor with the same options, locally where it can (above), else by a full
/// preprocess. The editor itself is not changed (its positions are brought up to date) and the
/// new one shares nothing mutable with it. Throws what Editor(Mesh, EditorOptions) throws.
BakeResult bake(Editor& editor, const BakeOptions& options = {});

} // namespace remora
