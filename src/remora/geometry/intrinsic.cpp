#include "remora/geometry/intrinsic.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/geometry/laplacian.h"

namespace remora {
namespace {

/// Area of a triangle from its edge lengths (Kahan's stable form of Heron's formula); 0 when the
/// lengths violate the triangle inequality.
double area_from_lengths(double a, double b, double c) {
  std::array<double, 3> s{a, b, c};
  std::sort(s.begin(), s.end(), std::greater<>());
  const double x = s[0], y = s[1], z = s[2];
  const double q = (x + (y + z)) * (z - (x - y)) * (z + (x - y)) * (x + (y - z));
  return q > 0.0 ? 0.25 * std::sqrt(q) : 0.0;
}

/// cot of the angle opposite the side of length a, in the triangle with sides a, b, c.
double cot_opposite(double a, double b, double c) {
  const double area = area_from_lengths(a, b, c);
  if (!(area > 0.0)) return 0.0;
  return (b * b + c * c - a * a) / (4.0 * area);
}

struct IntrinsicMesh {
  Mesh mesh;
  std::vector<double> length; // by edge idx

  double len(HalfedgeHandle h) const {
    return length[static_cast<std::size_t>(mesh.edge_handle(h).idx())];
  }
  /// cot of the corner opposite h in h's face (0 for a boundary halfedge).
  double cot(HalfedgeHandle h) const {
    if (mesh.is_boundary(h)) return 0.0;
    const HalfedgeHandle n = mesh.next_halfedge_handle(h);
    return cot_opposite(len(h), len(n), len(mesh.next_halfedge_handle(n)));
  }
  double weight(EdgeHandle e) const {
    return 0.5 * (cot(mesh.halfedge_handle(e, 0)) + cot(mesh.halfedge_handle(e, 1)));
  }
  /// The length of the other diagonal of the quad around e, from the planar layout of its two
  /// triangles.
  double flipped_length(EdgeHandle e) const {
    const HalfedgeHandle h = mesh.halfedge_handle(e, 0);
    const HalfedgeHandle g = mesh.halfedge_handle(e, 1);
    const double ab = len(h);
    const double bc = len(mesh.next_halfedge_handle(h));
    const double ca = len(mesh.prev_halfedge_handle(h));
    const double ad = len(mesh.next_halfedge_handle(g));
    const double db = len(mesh.prev_halfedge_handle(g));
    const double cx = (ab * ab + ca * ca - bc * bc) / (2.0 * ab);
    const double cy = std::sqrt(std::max(0.0, ca * ca - cx * cx));
    const double dx = (ab * ab + ad * ad - db * db) / (2.0 * ab);
    const double dy = -std::sqrt(std::max(0.0, ad * ad - dx * dx));
    return std::hypot(cx - dx, cy - dy);
  }
};

constexpr double kTolerance = 1e-12; // on cot α + cot β, which is scale-free

// Mollify (Sharp & Crane 2020, §4.5): adds the smallest ε with l_i + l_j >= l_k + δ in every
// face, δ = factor × the mean edge length, to every length; returns ε.
double mollify(IntrinsicMesh& im, double factor) {
  const Mesh& m = im.mesh;
  double total = 0.0;
  std::size_t count = 0;
  for (const EdgeHandle e : m.edges()) {
    im.length[static_cast<std::size_t>(e.idx())] = m.calc_edge_length(e);
    total += im.length[static_cast<std::size_t>(e.idx())];
    ++count;
  }
  const double delta = factor * (count > 0 ? total / double(count) : 0.0);
  double epsilon = 0.0;
  for (const FaceHandle f : m.faces()) {
    const HalfedgeHandle h0 = m.halfedge_handle(f);
    const HalfedgeHandle h1 = m.next_halfedge_handle(h0);
    const std::array<double, 3> l{im.len(h0), im.len(h1), im.len(m.next_halfedge_handle(h1))};
    for (int k = 0; k < 3; ++k)
      epsilon = std::max(epsilon, delta - (l[(k + 1) % 3] + l[(k + 2) % 3] - l[k]));
  }
  for (double& l : im.length) l += epsilon;
  return epsilon;
}

// Flips to intrinsic Delaunay: every interior edge with cot α + cot β < 0, at most
// max_flips_per_edge times each; counts negative_before and flips in `out`.
void flip_to_delaunay(IntrinsicMesh& im, int max_flips_per_edge, IntrinsicLaplacian& out) {
  Mesh& m = im.mesh;
  std::vector<EdgeHandle> stack;
  std::vector<char> queued(m.n_edges(), 0);
  for (const EdgeHandle e : m.edges()) {
    if (m.is_boundary(e)) continue;
    if (im.weight(e) < 0.0) {
      ++out.negative_before;
      stack.push_back(e);
      queued[static_cast<std::size_t>(e.idx())] = 1;
    }
  }
  std::vector<int> flips_of(m.n_edges(), 0);
  while (!stack.empty()) {
    const EdgeHandle e = stack.back();
    stack.pop_back();
    queued[static_cast<std::size_t>(e.idx())] = 0;
    if (m.is_boundary(e) || !(im.weight(e) < -kTolerance)) continue;
    if (flips_of[static_cast<std::size_t>(e.idx())] >= max_flips_per_edge) continue;
    if (!m.is_flip_ok(e)) continue;
    const double l = im.flipped_length(e);
    m.flip(e);
    im.length[static_cast<std::size_t>(e.idx())] = l;
    ++flips_of[static_cast<std::size_t>(e.idx())];
    ++out.flips;
    for (int side = 0; side < 2; ++side) {
      const HalfedgeHandle h = m.halfedge_handle(e, side);
      for (const HalfedgeHandle k : {m.next_halfedge_handle(h), m.prev_halfedge_handle(h)}) {
        const EdgeHandle n = m.edge_handle(k);
        if (!queued[static_cast<std::size_t>(n.idx())]) {
          queued[static_cast<std::size_t>(n.idx())] = 1;
          stack.push_back(n);
        }
      }
    }
  }
}

} // namespace

IntrinsicLaplacian intrinsic_delaunay_laplacian(const Mesh& mesh, const IntrinsicOptions& options) {
  if (!(options.mollify_factor > 0.0) || !std::isfinite(options.mollify_factor) ||
      options.max_flips_per_edge < 0)
    throw InvalidArgument(
        fmt::format("intrinsic_delaunay_laplacian: mollify_factor {} must be finite and > 0, "
                    "max_flips_per_edge {} >= 0",
                    options.mollify_factor, options.max_flips_per_edge));
  IntrinsicLaplacian out;
  IntrinsicMesh im{mesh, std::vector<double>(mesh.n_edges(), 0.0)};
  const Mesh& m = im.mesh;
  out.epsilon = mollify(im, options.mollify_factor);
  flip_to_delaunay(im, options.max_flips_per_edge, out);

  out.mass = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(m.n_vertices()));
  for (const FaceHandle f : m.faces()) {
    const HalfedgeHandle h0 = m.halfedge_handle(f);
    const HalfedgeHandle h1 = m.next_halfedge_handle(h0);
    const HalfedgeHandle h2 = m.next_halfedge_handle(h1);
    const double third = area_from_lengths(im.len(h0), im.len(h1), im.len(h2)) / 3.0;
    for (const HalfedgeHandle h : {h0, h1, h2}) out.mass[m.to_vertex_handle(h).idx()] += third;
  }
  std::vector<double> weights(m.n_edges(), 0.0);
  for (const EdgeHandle e : m.edges()) {
    double w = im.weight(e);
    if (w < 0.0 && m.is_boundary(e)) {
      // A boundary edge cannot be flipped; an obtuse (up to 180°) corner opposite it would give
      // an unbounded negative weight. Clamping keeps (M + t L) an M-matrix.
      w = 0.0;
      ++out.clamped_boundary;
    } else if (w < -kTolerance) {
      ++out.negative_after;
    }
    weights[static_cast<std::size_t>(e.idx())] = w;
  }
  out.weights = weights_matrix(m, weights); // sums parallel intrinsic edges
  return out;
}

} // namespace remora
