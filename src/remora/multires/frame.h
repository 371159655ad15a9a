// Step 7 of the editor, one frame (Botsch & Kobbelt 2004 §6; editor.h): the blend of the basis
// functions into the base's free vertices, the base's normals where they can change, and the
// Phong decode of the details. All three run once per handle move, so they are written for
// memory traffic: the basis is read once, row by row; each face's normal is computed once; a
// base vertex's position and normal lie side by side (one read per corner of a decode), and
// the details are stored compactly in the order of their outputs.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "remora/multires/phong.h"

namespace remora {

/// The basis functions, one row per free base vertex (n_free × (3 + 4h)), row-major so that a
/// vertex's coefficients lie together.
using BasisRows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// The base as the frame reads it, a row per base vertex: its position (columns 0-2) and its
/// unit normal (columns 3-5).
using FrameRows = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>;

/// Positions and normals (n × 3 each) side by side; throws InvalidArgument for other shapes.
FrameRows frame_rows(const Eigen::MatrixXd& positions, const Eigen::MatrixXd& normals);

/// frame(free_vertices[i], 0..2) = basis.row(i) · coefficients for every i: the blend
/// X_free = Φ C of editor.h. coefficients: (3 + 4h) × 3. Parallel over the rows with `threads`
/// threads (0 = all). Sizes are the caller's contract (checked in debug builds only).
void blend_basis(const BasisRows& basis, const Eigen::MatrixXd& coefficients,
                 const std::vector<int>& free_vertices, FrameRows& frame, int threads);

/// What a frame's normals need, built once per region: `vertices`, whose normals can change;
/// `faces`, every face around one of them, and `corners`, each of those faces' corners (read in
/// sequence by a frame); `ring`, for vertices[i] the positions in `faces` of its faces,
/// ring[ring_begin[i] .. ring_begin[i + 1]), in the order of topology.vertex_faces.
struct NormalPlan {
  std::vector<int> vertices, faces, ring_begin, ring;
  std::vector<std::array<int, 3>> corners;
};

/// The plan for the normals of `vertices` (base vertex ids).
NormalPlan plan_normals(const TriangleTopology& topology, const std::vector<int>& vertices);

/// frame(v, 3..5) for every v of plan.vertices, from the positions frame(·, 0..2), as
/// vertex_normals() computes them (the same sums in the same order, so bit for bit the same):
/// the normalized sum of the faces' cross products, (0, 0, 0) where it vanishes. `scratch` holds
/// the faces' cross products between calls.
void update_normals(const NormalPlan& plan, FrameRows& frame, std::vector<double>& scratch,
                    int threads);

/// The details of a region as the frame decodes them: per output, its base face (and that face's
/// corners), barycentric coordinates and offset; the rare residuals (phong.h) apart. The records
/// are in the order of their faces' first corners, so that a frame reads the base's rows nearly
/// in sequence (and scatters its writes instead).
struct FrameDetails {
  struct Record {
    std::array<double, 3> bary;
    double offset;
    int face;
    int residual; ///< index into `residuals`, or -1
    std::array<int, 3> corners;
  };
  std::vector<Record> records;
  std::vector<std::array<double, 3>> residuals;
  std::vector<int> outputs;             ///< record i decodes into row outputs[i]
  std::vector<Eigen::Vector3d> offsets; ///< per record, added (DetailMode::Displacement), or empty
};

/// The frame's form of `details` (decoding into rows `outputs`) on the base of `topology`. Without
/// `keep_offsets` every detail decodes to its base point (offsets and residuals dropped:
/// DetailMode::None and Displacement); `added`, when not empty, is added per detail. Throws
/// InvalidArgument for mismatched sizes.
FrameDetails frame_details(const TriangleTopology& topology,
                           const std::vector<PhongDetail>& details, const std::vector<int>& outputs,
                           bool keep_offsets, const std::vector<Eigen::Vector3d>& added = {});

/// positions.row(details.outputs[i]) = the decode of record i on `frame` for every i, the same
/// doubles as decode_phong() on the frame's positions and normals. Parallel with `threads`.
void decode_details(const FrameRows& frame, const FrameDetails& details, Eigen::MatrixXd& positions,
                    int threads);

} // namespace remora
