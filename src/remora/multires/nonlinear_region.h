// The editor's method nonlinear for one region (multires/editor.h): the fine deformer
// (multires/nonlinear.h), for a large support its coarse preview (multires/nonlinear_preview.h),
// which of them a frame runs, and the fall-back to the linear result.
//
// A frame starts from the linear result (the blend of the basis functions). After a handle
// moved, the preview (when there is one) iterates within the frame's budget and its correction
// of the linear result is shown; once it has finished and the handles rest, the fine deformer
// starts from that and iterates until converged. Without a preview the fine deformer starts from
// the linear result at once. A failure (a factorization at set-up, a non-finite iterate) shows
// the linear result instead, with the reason in fallback(); a new move tries again.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "remora/mesh/mesh.h"
#include "remora/multires/nonlinear.h"
#include "remora/multires/nonlinear_preview.h"
#include "remora/multires/phong.h"
#include "remora/remesh/remesh.h"

namespace remora {

/// The coarse remesh of the base that a preview of the free base vertices `free_vertices` uses:
/// the faces of B within a margin of them (three coarse edge lengths, counted in rings of B's
/// vertices) cut out and remeshed at options.preview_vertices' share of the free vertices (an
/// edge length at least twice the base's: coarse_length()), so that its cost follows the
/// support, not the base; the whole of B when that part holds more than half its faces. With
/// both correspondences on the whole of B: output_on_input on B's
/// faces, input_on_output a point on the coarse mesh for every vertex of the cut-out part and an
/// invalid face for the others. `topology`, `points` (n × 3) and `base_length` (the mean edge
/// length) are B's. Throws what remesh() and sub_mesh() (multires/face_patch.h) throw.
RemeshResult make_coarse_base(const Mesh& base, const TriangleTopology& topology,
                              const Eigen::MatrixXd& points, double base_length,
                              const std::vector<int>& free_vertices,
                              const NonlinearOptions& options);
/// Whether `coarse`, made by make_coarse_base() for some region, serves the free base vertices
/// `free_vertices` as well: an edge length within 50 % of the one they call for, and every
/// vertex within two coarse edge lengths of them located on it.
bool coarse_base_serves(const RemeshResult& coarse, const Mesh& base,
                        const TriangleTopology& topology, double base_length,
                        const std::vector<int>& free_vertices, const NonlinearOptions& options);
/// The edge length make_coarse_base() aims at for `free_vertices` on a base of mean edge length
/// `base_length`.
double coarse_length(double base_length, std::size_t free_vertices,
                     const NonlinearOptions& options);

class NonlinearRegion {
public:
  /// As NonlinearDeformer's, plus `coarse` (nullptr: no preview). Does not throw for a failing
  /// set-up: fallback() says why, and frames show the linear result.
  NonlinearRegion(const Mesh& base, const RemeshResult* coarse, const Eigen::MatrixXd& rest,
                  const std::vector<int>& labels, const Eigen::MatrixXd& handle_weights,
                  const NonlinearOptions& options);
  ~NonlinearRegion();

  /// One frame: `base` (every base vertex) holds the linear result under `transforms`; its free
  /// rows are replaced. `moved`: the transforms changed since the last frame; with a preview and
  /// a finite budget such a frame stops at the preview, and the fine level starts in a later one.
  /// `interrupt`: as for NonlinearDeformer::solve(), also between the levels.
  void frame(const std::vector<AffineMap>& transforms, bool moved, double budget_ms,
             RowPoints& base, const std::function<bool()>& interrupt = {});
  /// Nothing left to iterate under the current transforms (or fallen back).
  bool finished() const;
  /// The last frame's iterations, of the level it ran last.
  const NonlinearStats& stats() const { return stats_; }
  /// "fine" or "coarse": the level the last frame showed.
  const std::string& level() const { return level_; }
  /// Why the linear result is shown, or empty.
  const std::string& fallback() const { return fallback_; }
  std::size_t coarse_free_vertices() const;

private:
  std::unique_ptr<NonlinearDeformer> fine_;
  std::unique_ptr<NonlinearPreview> preview_;
  std::vector<int> free_;
  std::string setup_error_, fallback_, level_ = "fine";
  NonlinearStats stats_;
  bool fine_stale_ = true; // the fine deformer has not started from the current transforms
  RowPoints linear_;       // the frame's linear result (free rows)
};

} // namespace remora
