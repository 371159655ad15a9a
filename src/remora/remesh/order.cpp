// Compaction and renumbering of the working mesh. Large meshes are renumbered along a Z-order
// curve so that neighbours sit close in memory: the walks, the smoothing and the fine-tuning then
// read memory close to what they read last.
#include <algorithm>
#include <cstdint>
#include <limits>

#include "remora/remesh/remesher.h"

namespace remora::remesh_detail {

namespace {

// 21 bits -> every third bit of 63.
std::uint64_t spread_bits(std::uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

// The live vertices, old index by new index: along the Z-order (Morton) curve of their positions
// when `spatially`, else in their order.
std::vector<int> vertex_order(const Mesh& mesh, bool spatially) {
  Vec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  keyed.reserve(mesh.n_vertices());
  for (auto v : mesh.vertices()) { // live vertices only
    if (!spatially) {
      keyed.push_back({0, static_cast<std::uint32_t>(v.idx())});
      continue;
    }
    const Vec3 q = mesh.point(v) - lo;
    std::uint64_t key = 0;
    for (int d = 0; d < 3; ++d) {
      const double extent = hi[d] - lo[d];
      const double unit = extent > 0 ? std::clamp(q[d] / extent, 0.0, 1.0) : 0.0;
      key |= spread_bits(static_cast<std::uint64_t>(unit * 2097151.0)) << d;
    }
    keyed.push_back({key, static_cast<std::uint32_t>(v.idx())});
  }
  if (spatially) std::sort(keyed.begin(), keyed.end());
  std::vector<int> order(keyed.size());
  for (std::size_t r = 0; r < keyed.size(); ++r) order[r] = static_cast<int>(keyed[r].second);
  return order;
}

// The live faces by their smallest new vertex index, ties in old order (a counting sort); fmap
// gets each old face's new index.
std::vector<int> face_order(const Mesh& mesh, const std::vector<int>& vmap, std::size_t nv,
                            std::vector<int>& fmap) {
  const std::size_t nf_old = mesh.n_faces();
  std::vector<std::uint32_t> first(nv + 1, 0);
  std::vector<int> face_key(nf_old, -1);
  for (auto f : mesh.faces()) {
    const auto fv = face_vertices(mesh, f);
    const int m = std::min({vmap[fv[0].idx()], vmap[fv[1].idx()], vmap[fv[2].idx()]});
    face_key[f.idx()] = m;
    ++first[static_cast<std::size_t>(m) + 1];
  }
  for (std::size_t r = 0; r < nv; ++r) first[r + 1] += first[r];
  std::vector<int> order(first[nv], -1);
  fmap.assign(nf_old, -1);
  for (std::size_t f = 0; f < nf_old; ++f)
    if (face_key[f] >= 0) {
      const std::uint32_t slot = first[static_cast<std::size_t>(face_key[f])]++;
      order[slot] = static_cast<int>(f);
      fmap[f] = static_cast<int>(slot);
    }
  return order;
}

// The live edges by first use in `faces` (every live edge has a face); emap gets each old edge's
// new index.
std::vector<int> edge_order(const Mesh& mesh, const std::vector<int>& faces,
                            std::vector<int>& emap) {
  emap.assign(mesh.n_edges(), -1);
  std::vector<int> order;
  order.reserve(mesh.n_edges());
  for (int f : faces)
    for (auto h : mesh.fh_range(FaceHandle(f))) {
      const int e = h.idx() / 2;
      if (emap[static_cast<std::size_t>(e)] < 0) {
        emap[static_cast<std::size_t>(e)] = static_cast<int>(order.size());
        order.push_back(e);
      }
    }
  return order;
}

} // namespace

// Each face keeps its first halfedge (its corners keep their order). The half-edge structure is
// copied through the index maps in linear time, no rebuild from triangles.
Mesh copy_in_order(const Mesh& mesh, bool spatially, MeshOrder& order) {
  order.vertices = vertex_order(mesh, spatially);
  const std::size_t nv = order.vertices.size();
  std::vector<int> vmap(mesh.n_vertices(), -1), fmap, emap;
  for (std::size_t r = 0; r < nv; ++r)
    vmap[static_cast<std::size_t>(order.vertices[r])] = static_cast<int>(r);
  order.faces = face_order(mesh, vmap, nv, fmap);
  order.edges = edge_order(mesh, order.faces, emap);
  // OpenMesh numbers the halfedges of edge e as 2e and 2e + 1.
  auto hmap = [&](HalfedgeHandle h) {
    return HalfedgeHandle(2 * emap[static_cast<std::size_t>(h.idx() / 2)] + (h.idx() & 1));
  };

  Mesh out;
  out.reserve(nv, order.edges.size(), order.faces.size());
  for (std::size_t r = 0; r < nv; ++r) out.new_vertex(mesh.point(VertexHandle(order.vertices[r])));
  for (int e : order.edges) {
    const HalfedgeHandle h0 = mesh.halfedge_handle(EdgeHandle(e), 0);
    out.new_edge(VertexHandle(vmap[mesh.from_vertex_handle(h0).idx()]),
                 VertexHandle(vmap[mesh.to_vertex_handle(h0).idx()]));
  }
  for (int f : order.faces) {
    const FaceHandle fh = out.new_face();
    out.set_halfedge_handle(fh, hmap(mesh.halfedge_handle(FaceHandle(f))));
  }
  for (std::size_t i = 0; i < order.edges.size(); ++i)
    for (int side = 0; side < 2; ++side) {
      const HalfedgeHandle h(2 * order.edges[i] + side);
      const HalfedgeHandle hn(static_cast<int>(2 * i) + side);
      out.set_next_halfedge_handle(hn, hmap(mesh.next_halfedge_handle(h)));
      const FaceHandle f = mesh.face_handle(h);
      if (f.is_valid())
        out.set_face_handle(hn, FaceHandle(fmap[static_cast<std::size_t>(f.idx())]));
    }
  for (std::size_t r = 0; r < nv; ++r) {
    const HalfedgeHandle h = mesh.halfedge_handle(VertexHandle(order.vertices[r]));
    if (h.is_valid()) out.set_halfedge_handle(VertexHandle(static_cast<int>(r)), hmap(h));
  }
  return out;
}

// Below kSpatialOrderFaces the whole mesh stays in cache and the spatial order only costs; the
// compaction pays even there: split vertices sit at the end, away from their neighbours. After
// the cycles, with many deleted elements, the copy is faster than OpenMesh's garbage collection.
void compact(Remesher& rm) {
  MeshOrder order;
  Mesh out = copy_in_order(rm.mesh, rm.live_faces > kSpatialOrderFaces, order);
  rm.adopt_renumbered(std::move(out), order);
  rebind_points(rm);
  rm.live_faces = rm.mesh.n_faces();
}

// The repairs delete a few elements: OpenMesh's in-place garbage collection is cheaper than a
// copy for those.
void remove_deleted(Remesher& rm) {
  if (rm.live_faces == rm.mesh.n_faces()) return;
  rm.mesh.garbage_collection();
  rebind_points(rm);
  rm.live_faces = rm.mesh.n_faces();
}

void to_input_order(RemeshResult& result, const Mesh& input, const MeshOrder& order) {
  for (SurfacePoint& p : result.output_on_input)
    if (p.face.is_valid()) p.face = FaceHandle(order.faces[static_cast<std::size_t>(p.face.idx())]);
  if (!result.input_on_output.empty()) {
    std::vector<SurfacePoint> by_input(input.n_vertices());
    for (std::size_t r = 0; r < order.vertices.size(); ++r)
      by_input[static_cast<std::size_t>(order.vertices[r])] = result.input_on_output[r];
    result.input_on_output = std::move(by_input);
  }
}

} // namespace remora::remesh_detail
