// The local bake's last step (bake.h): the remeshed patch stitched into the base, both
// correspondences carried over and mended where the base moved, and the base's figures.
#include <fmt/format.h>

#include "remora/common/parallel.h"
#include "remora/common/timer.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/locate.h"
#include "remora/mesh/splice.h"
#include "remora/mesh/topology.h"
#include "remora/multires/bake_steps.h"

namespace remora::bake_detail {

namespace {

Vec3 row_point(const Eigen::MatrixXd& p, Eigen::Index i) {
  return Vec3(p(i, 0), p(i, 1), p(i, 2));
}

// `to`: a copy of `from` with vertex v at row v of `points` wherever `flags[v]` is set.
void copy_moved(const Mesh& from, const std::vector<char>& flags, const Eigen::MatrixXd& points,
                Mesh& to) {
  to = from;
  for (std::size_t v = 0; v < flags.size(); ++v)
    if (flags[v])
      to.set_point(VertexHandle(static_cast<int>(v)),
                   row_point(points, static_cast<Eigen::Index>(v)));
}

// `base`: B' with the remeshed patch in place of the old one (splice(): the old base's numbering
// kept outside the patch); its correspondence to the input. An output argument: OpenMesh's
// meshes have no move assignment, so a returned mesh would be copied into place.
void stitched_base(const Bake& b, const PatchMeshes& m, const RemeshPatchResult& r, Mesh& base,
                   std::vector<SurfacePoint>& base_on_input, SpliceMap& map) {
  copy_moved(b.old.base, b.moved, b.base_points, base);
  std::vector<int> origin(r.origin.size(), -1);
  for (std::size_t o = 0; o < origin.size(); ++o)
    if (r.origin[o] >= 0) origin[o] = m.patch_vertices[static_cast<std::size_t>(r.origin[o])];
  map = splice(base, b.patch, r.mesh, origin);
  base_on_input.assign(base.n_vertices(), SurfacePoint{FaceHandle(), {1.0, 0.0, 0.0}});
  for (std::size_t v = 0; v < map.vertices.size(); ++v)
    if (map.vertices[v] >= 0)
      base_on_input[static_cast<std::size_t>(map.vertices[v])] = b.old.base_on_input[v];
  for (std::size_t o = 0; o < origin.size(); ++o) {
    if (origin[o] >= 0) continue;
    const SurfacePoint& sp = r.output_on_reference[o];
    base_on_input[static_cast<std::size_t>(map.patch_vertices[o])] = {
        FaceHandle(m.reference_faces[static_cast<std::size_t>(sp.face.idx())]), sp.bary};
  }
}

// Each input vertex's location on the new base: the remesh's closest point for those it
// tracked, else its old face (renumbered), walked to S' again where the base or S' moved there.
std::vector<SurfacePoint> mend_input_on_base(const Bake& b, const Mesh& base, const PatchMeshes* m,
                                             const RemeshPatchResult* r, const SpliceMap* map) {
  const std::size_t n = b.old.input_on_base.size();
  std::vector<SurfacePoint> out(n);
  std::vector<int> tracked(m ? n : 0, -1);
  if (m)
    for (std::size_t l = 0; l < m->reference_vertices.size(); ++l)
      tracked[static_cast<std::size_t>(m->reference_vertices[l])] = static_cast<int>(l);
  std::vector<int> walk;
  for (std::size_t i = 0; i < n; ++i) {
    const SurfacePoint& sp = b.old.input_on_base[i];
    if (!sp.face.is_valid()) continue;
    const auto f = static_cast<std::size_t>(sp.face.idx());
    if (m && tracked[i] >= 0) {
      const SurfacePoint& on = r->reference_on_output[static_cast<std::size_t>(tracked[i])];
      if (on.face.is_valid()) {
        out[i] = {FaceHandle(map->patch_faces[static_cast<std::size_t>(on.face.idx())]), on.bary};
        continue;
      }
    }
    if (m && b.patch[f])
      throw NotLocal(fmt::format("input vertex {} lies on the patch but was not tracked", i));
    out[i] = {FaceHandle(map ? map->faces[f] : static_cast<int>(f)), sp.bary};
    const auto& fv = b.old.topology.faces[f];
    if (b.in_band[i] || b.moved[static_cast<std::size_t>(fv[0])] ||
        b.moved[static_cast<std::size_t>(fv[1])] || b.moved[static_cast<std::size_t>(fv[2])])
      walk.push_back(static_cast<int>(i));
  }
  b.report.rewalked_input_vertices = walk.size();
  parallel_for(walk.size(), b.options.threads, [&](std::size_t k) {
    const auto i = static_cast<std::size_t>(walk[k]);
    out[i] = walk_to_closest(base, row_point(b.smooth, static_cast<Eigen::Index>(i)), out[i].face);
  });
  return out;
}

// The new base's TriangleTopology, as triangle_topology() reads it: the old faces renumbered
// through the splice (which keeps a kept face's halfedge, so its corners' order), the patch's
// faces and the kept faces across from a removed one read from the mesh, the vertex-face lists
// rebuilt.
TriangleTopology carried_topology(const Bake& b, const Mesh& base, const SpliceMap& map) {
  TriangleTopology t;
  const std::size_t nf = base.n_faces();
  t.faces.resize(nf);
  t.across.resize(nf);
  std::vector<char> read(nf, 0);
  for (const int f : map.patch_faces) read[static_cast<std::size_t>(f)] = 1;
  const TriangleTopology& old = b.old.topology;
  for (std::size_t f = 0; f < old.faces.size(); ++f) {
    const int to = map.faces[f];
    if (to < 0) continue;
    const auto i = static_cast<std::size_t>(to);
    for (std::size_t k = 0; k < 3; ++k) {
      t.faces[i][k] = map.vertices[static_cast<std::size_t>(old.faces[f][k])];
      const int g = old.across[f][k];
      t.across[i][k] = g < 0 ? -1 : map.faces[static_cast<std::size_t>(g)];
      if (g >= 0 && t.across[i][k] < 0) read[i] = 1;
    }
  }
  for (std::size_t f = 0; f < nf; ++f)
    if (read[f]) read_face_topology(base, f, t);
  build_vertex_faces(t, base.n_vertices());
  return t;
}

} // namespace

BaseChange base_change(const Bake& b, const SpliceMap* map) {
  BaseChange c;
  if (map) {
    c.vertex_map = map->vertices;
    c.new_faces = map->patch_faces;
  }
  const TriangleTopology& t = b.old.topology;
  for (std::size_t f = 0; f < t.faces.size(); ++f) {
    const auto& fv = t.faces[f];
    if (b.patch[f]) {
      c.old_faces.push_back(static_cast<int>(f));
    } else if (b.moved[static_cast<std::size_t>(fv[0])] ||
               b.moved[static_cast<std::size_t>(fv[1])] ||
               b.moved[static_cast<std::size_t>(fv[2])]) {
      c.old_faces.push_back(static_cast<int>(f));
      c.new_faces.push_back(map ? map->faces[f] : static_cast<int>(f));
    }
  }
  return c;
}

namespace {

// The base's edges with a negative cotan weight: the old ones where no face around them changed,
// and those around the changed faces measured again.
std::vector<std::pair<int, int>> negative_edges(const Bake& b, const Mesh& base,
                                                const SpliceMap* map, const BaseChange& change) {
  std::vector<char> changed(base.n_faces(), 0);
  for (const int f : change.new_faces) changed[static_cast<std::size_t>(f)] = 1;
  auto near_change = [&](EdgeHandle e) {
    for (int side = 0; side < 2; ++side) {
      const FaceHandle f = base.face_handle(base.halfedge_handle(e, side));
      if (f.is_valid() && changed[static_cast<std::size_t>(f.idx())]) return true;
    }
    return false;
  };
  std::vector<std::pair<int, int>> out;
  for (const auto& [a, c] : b.old.negative_edges) {
    const int x = map ? map->vertices[static_cast<std::size_t>(a)] : a;
    const int y = map ? map->vertices[static_cast<std::size_t>(c)] : c;
    if (x < 0 || y < 0) continue;
    const HalfedgeHandle h = base.find_halfedge(VertexHandle(x), VertexHandle(y));
    if (h.is_valid() && !near_change(base.edge_handle(h)))
      out.emplace_back(std::min(x, y), std::max(x, y));
  }
  std::vector<char> seen(base.n_edges(), 0);
  for (std::size_t f = 0; f < changed.size(); ++f) {
    if (!changed[f]) continue;
    for (const HalfedgeHandle h : base.fh_range(FaceHandle(static_cast<int>(f)))) {
      const EdgeHandle e = base.edge_handle(h);
      if (seen[static_cast<std::size_t>(e.idx())]) continue;
      seen[static_cast<std::size_t>(e.idx())] = 1;
      if (cotan_weight(base, e) < 0.0) {
        const int x = base.from_vertex_handle(h).idx(), y = base.to_vertex_handle(h).idx();
        out.emplace_back(std::min(x, y), std::max(x, y));
      }
    }
  }
  return out;
}

} // namespace

// The base's figures for the report: the topological ones (the bake keeps the topology) from the
// old report, the others updated where the base changed (base_figures.h).
void base_figures(const Bake& b, const BaseChange& change, EditorParts& parts,
                  const SpliceMap* map) {
  EditReport& r = parts.report;
  const EditReport& old = b.old.report;
  r.remeshed = true;
  r.input_vertices = old.input_vertices;
  r.input_faces = old.input_faces;
  r.sigma = old.sigma;
  r.sigma_min = old.sigma_min;
  r.sigma_capped_vertices = old.sigma_capped_vertices;
  r.sigma_capped_loops = old.sigma_capped_loops;
  r.intrinsic_flips = old.intrinsic_flips;
  r.input_negative_weights = old.input_negative_weights;
  r.base_target_length = old.base_target_length;
  r.base_vertices = parts.base.n_vertices();
  r.base_faces = parts.base.n_faces();
  parts.negative_edges = negative_edges(b, parts.base, map, change);
  update_mesh_figures(b.old.base, old.base_quality, parts.base, change, r.base_quality);
  if (r.base_quality.component_topology.size() == 1) {
    ComponentTopology& c = r.base_quality.component_topology.front();
    c.vertices = static_cast<int>(r.base_quality.vertices);
    c.edges = static_cast<int>(r.base_quality.edges);
    c.faces = static_cast<int>(r.base_quality.faces);
  } else {
    r.base_quality.component_topology = component_topology(parts.base);
  }
}

void stitch(const Bake& b, const PatchMeshes* m, const RemeshPatchResult* r, SpliceMap& map,
            EditorParts& parts) {
  if (m) {
    stitched_base(b, *m, *r, parts.base, parts.base_on_input, map);
  } else {
    copy_moved(b.old.base, b.moved, b.base_points, parts.base);
    parts.base_on_input = b.old.base_on_input;
  }
}

void carry_input(const Bake& b, EditorParts& parts) {
  copy_moved(b.old.input, b.in_band, b.input_positions, parts.input);
  parts.input_topology = b.old.input_topology;
  parts.filter = b.old.filter;
}

void mend(Bake& b, const PatchMeshes* m, const RemeshPatchResult* r, const SpliceMap* map,
          EditorParts& parts) {
  parts.input_on_base = mend_input_on_base(b, parts.base, m, r, map);
  parts.input_positions = std::move(b.input_positions); // carry_input() has read it
  parts.smooth = std::move(b.smooth);
  parts.topology = map ? carried_topology(b, parts.base, *map) : b.old.topology;
  parts.base_rest = positions_matrix(parts.base);
}

} // namespace remora::bake_detail
