// splice(): the patch's half-edge structure written into the places of the removed elements, then
// the last elements moved into the places left over (mesh/splice.h).
#include "remora/mesh/splice.h"

#include <algorithm>
#include <functional>
#include <string>

#include "remora/common/error.h"

namespace remora {

namespace {

// What splice() works out before it changes anything.
struct Plan {
  std::vector<int> faces, edges, vertices; // removed, ascending
  std::vector<char> edge_gone;             // per edge of the mesh
  std::vector<HalfedgeHandle> matched;     // per patch edge on its boundary: the mesh halfedge
                                           // of its inner (face) side
};

Plan plan_splice(const Mesh& mesh, const std::vector<char>& removed, const Mesh& patch,
                 const std::vector<int>& origin) {
  const auto nv = static_cast<int>(mesh.n_vertices());
  if (removed.size() != mesh.n_faces() || origin.size() != patch.n_vertices())
    throw InvalidArgument("splice: " + std::to_string(removed.size()) + " face flags for " +
                          std::to_string(mesh.n_faces()) + " faces, " +
                          std::to_string(origin.size()) + " origins for " +
                          std::to_string(patch.n_vertices()) + " patch vertices");
  Plan p;
  p.edge_gone.assign(mesh.n_edges(), 0);
  std::vector<char> is_origin(mesh.n_vertices(), 0), seen(mesh.n_vertices(), 0);
  for (const int o : origin) {
    if (o < -1 || o >= nv) throw InvalidArgument("splice: an origin is out of range");
    if (o >= 0) is_origin[static_cast<std::size_t>(o)] = 1;
  }
  std::size_t border = 0;
  for (std::size_t f = 0; f < removed.size(); ++f) {
    if (!removed[f]) continue;
    const FaceHandle fh(static_cast<int>(f));
    if (mesh.status(fh).deleted()) throw InvalidArgument("splice: the mesh has deleted faces");
    p.faces.push_back(static_cast<int>(f));
    for (const HalfedgeHandle h : mesh.fh_range(fh)) {
      const FaceHandle g = mesh.opposite_face_handle(h);
      if (!g.is_valid() || !removed[static_cast<std::size_t>(g.idx())]) {
        ++border;
      } else if (!p.edge_gone[static_cast<std::size_t>(mesh.edge_handle(h).idx())]) {
        p.edge_gone[static_cast<std::size_t>(mesh.edge_handle(h).idx())] = 1;
        p.edges.push_back(mesh.edge_handle(h).idx());
      }
      const VertexHandle v = mesh.to_vertex_handle(h);
      const auto vi = static_cast<std::size_t>(v.idx());
      if (seen[vi] || is_origin[vi]) continue;
      seen[vi] = 1;
      for (const FaceHandle k : mesh.vf_range(v))
        if (!removed[static_cast<std::size_t>(k.idx())])
          throw InvalidArgument("splice: vertex " + std::to_string(v.idx()) +
                                " keeps faces outside the removed ones but has no patch vertex");
      p.vertices.push_back(v.idx());
    }
  }
  std::sort(p.edges.begin(), p.edges.end());
  std::sort(p.vertices.begin(), p.vertices.end());
  // Every boundary edge of the patch matches a border halfedge of the removed faces.
  p.matched.assign(patch.n_edges(), HalfedgeHandle());
  std::size_t patch_border = 0;
  for (const EdgeHandle e : patch.edges()) {
    if (!patch.is_boundary(e)) continue;
    ++patch_border;
    HalfedgeHandle inner = patch.halfedge_handle(e, 0);
    if (patch.is_boundary(inner)) inner = patch.opposite_halfedge_handle(inner);
    const int x = origin[static_cast<std::size_t>(patch.from_vertex_handle(inner).idx())];
    const int y = origin[static_cast<std::size_t>(patch.to_vertex_handle(inner).idx())];
    const HalfedgeHandle h =
        x >= 0 && y >= 0 ? mesh.find_halfedge(VertexHandle(x), VertexHandle(y)) : HalfedgeHandle();
    const FaceHandle f = h.is_valid() ? mesh.face_handle(h) : FaceHandle();
    if (!f.is_valid() || !removed[static_cast<std::size_t>(f.idx())] ||
        p.edge_gone[static_cast<std::size_t>(mesh.edge_handle(h).idx())])
      throw InvalidArgument("splice: a boundary edge of the patch is no border edge of the "
                            "removed faces");
    p.matched[static_cast<std::size_t>(e.idx())] = h;
  }
  if (patch_border != border)
    throw InvalidArgument("splice: the patch's border has " + std::to_string(patch_border) +
                          " edges, the removed faces' " + std::to_string(border));
  return p;
}

// The places the patch's new elements take: the removed ones first, then new ones at the end;
// `owner` gets the patch element of each place (its index, encoded as -2 - index).
std::vector<int> places(const std::vector<int>& removed, std::size_t wanted,
                        const std::function<int()>& append, std::vector<int>& owner) {
  std::vector<int> out(wanted);
  for (std::size_t i = 0; i < wanted; ++i) {
    out[i] = i < removed.size() ? removed[i] : append();
    if (static_cast<std::size_t>(out[i]) >= owner.size())
      owner.resize(static_cast<std::size_t>(out[i]) + 1, -1);
    owner[static_cast<std::size_t>(out[i])] = -2 - static_cast<int>(i);
  }
  for (std::size_t i = wanted; i < removed.size(); ++i)
    owner[static_cast<std::size_t>(removed[i])] = -1; // left over
  return out;
}

// Moves the live elements from the end into the places left over (owner -1), each with
// `move(from, to)`, and returns the new count.
int close_gaps(std::vector<int>& owner, const std::function<void(int, int)>& move) {
  int last = static_cast<int>(owner.size()) - 1;
  for (int s = 0; s <= last; ++s) {
    if (owner[static_cast<std::size_t>(s)] != -1) continue;
    while (last > s && owner[static_cast<std::size_t>(last)] == -1) --last;
    if (last <= s) return s;
    move(last, s);
    owner[static_cast<std::size_t>(s)] = owner[static_cast<std::size_t>(last)];
    owner[static_cast<std::size_t>(last)] = -1;
    --last;
  }
  return last + 1;
}

void move_vertex(Mesh& mesh, int from, int to) {
  const VertexHandle a(from), b(to);
  mesh.set_point(b, mesh.point(a));
  mesh.status(b) = mesh.status(a);
  const HalfedgeHandle out = mesh.halfedge_handle(a);
  mesh.set_halfedge_handle(b, out);
  if (!out.is_valid()) return;
  HalfedgeHandle h = out;
  do {
    const HalfedgeHandle in = mesh.opposite_halfedge_handle(h);
    mesh.set_vertex_handle(in, b);
    h = mesh.next_halfedge_handle(in);
  } while (h != out);
}

void move_face(Mesh& mesh, int from, int to) {
  const FaceHandle a(from), b(to);
  mesh.status(b) = mesh.status(a);
  const HalfedgeHandle h0 = mesh.halfedge_handle(a);
  mesh.set_halfedge_handle(b, h0);
  HalfedgeHandle h = h0;
  do {
    mesh.set_face_handle(h, b);
    h = mesh.next_halfedge_handle(h);
  } while (h != h0);
}

void move_edge(Mesh& mesh, int from, int to) {
  auto map = [&](HalfedgeHandle h) {
    return h.idx() / 2 == from ? HalfedgeHandle(2 * to + (h.idx() & 1)) : h;
  };
  mesh.status(EdgeHandle(to)) = mesh.status(EdgeHandle(from));
  for (int side = 0; side < 2; ++side) {
    const HalfedgeHandle h(2 * from + side), g(2 * to + side);
    mesh.set_vertex_handle(g, mesh.to_vertex_handle(h));
    mesh.set_face_handle(g, mesh.face_handle(h));
    mesh.status(g) = mesh.status(h);
  }
  for (int side = 0; side < 2; ++side) {
    const HalfedgeHandle h(2 * from + side), g(2 * to + side);
    const HalfedgeHandle next = mesh.next_halfedge_handle(h), prev = mesh.prev_halfedge_handle(h);
    mesh.set_next_halfedge_handle(g, map(next));
    mesh.set_next_halfedge_handle(map(prev), g);
    const FaceHandle f = mesh.face_handle(h);
    if (f.is_valid() && mesh.halfedge_handle(f) == h) mesh.set_halfedge_handle(f, g);
    const VertexHandle v = mesh.from_vertex_handle(h);
    if (mesh.halfedge_handle(v) == h) mesh.set_halfedge_handle(v, g);
  }
}

// Where the patch's elements go in the mesh.
struct Placement {
  std::vector<int> vertex_owner, edge_owner, face_owner; // per place: its element (places())
  std::vector<int> new_vertices; // the patch's vertices without an origin, ascending
  std::vector<int> vmap, emap;   // per patch vertex and edge: its place (-1: a boundary edge)
  std::vector<int> fplace;       // per patch face: its place
};

// Chooses the places of the patch's new vertices, inner edges and faces: the removed elements',
// then new ones appended to `mesh`.
Placement place_patch(Mesh& mesh, const Plan& plan, const Mesh& patch,
                      const std::vector<int>& origin) {
  Placement at;
  at.vertex_owner.resize(mesh.n_vertices());
  at.edge_owner.resize(mesh.n_edges());
  at.face_owner.resize(mesh.n_faces());
  for (std::size_t i = 0; i < at.vertex_owner.size(); ++i) at.vertex_owner[i] = static_cast<int>(i);
  for (std::size_t i = 0; i < at.edge_owner.size(); ++i) at.edge_owner[i] = static_cast<int>(i);
  for (std::size_t i = 0; i < at.face_owner.size(); ++i) at.face_owner[i] = static_cast<int>(i);
  // Places for the patch's new vertices, inner edges and faces.
  std::vector<int> inner_edges;
  for (const VertexHandle v : patch.vertices())
    if (origin[static_cast<std::size_t>(v.idx())] < 0) at.new_vertices.push_back(v.idx());
  for (const EdgeHandle e : patch.edges())
    if (!patch.is_boundary(e)) inner_edges.push_back(e.idx());
  const std::vector<int> vplace = places(
      plan.vertices, at.new_vertices.size(), [&] { return mesh.new_vertex(Vec3(0, 0, 0)).idx(); },
      at.vertex_owner);
  const std::vector<int> eplace = places(
      plan.edges, inner_edges.size(),
      [&] { return mesh.new_edge(VertexHandle(0), VertexHandle(0)).idx() / 2; }, at.edge_owner);
  at.fplace = places(
      plan.faces, patch.n_faces(), [&] { return mesh.new_face().idx(); }, at.face_owner);
  // The patch's elements in the mesh's numbering.
  at.vmap.resize(patch.n_vertices());
  at.emap.assign(patch.n_edges(), -1);
  for (std::size_t i = 0; i < origin.size(); ++i) at.vmap[i] = origin[i];
  for (std::size_t i = 0; i < at.new_vertices.size(); ++i)
    at.vmap[static_cast<std::size_t>(at.new_vertices[i])] = vplace[i];
  for (std::size_t i = 0; i < inner_edges.size(); ++i)
    at.emap[static_cast<std::size_t>(inner_edges[i])] = eplace[i];
  return at;
}

// Writes the patch's half-edge structure into its places; the boundary side of its border keeps
// the mesh's own.
void write_patch(Mesh& mesh, const Plan& plan, const Mesh& patch, const std::vector<int>& origin,
                 const Placement& at) {
  auto hmap = [&](HalfedgeHandle h) {
    const auto e = static_cast<std::size_t>(h.idx() / 2);
    if (at.emap[e] >= 0) return HalfedgeHandle(2 * at.emap[e] + (h.idx() & 1));
    const HalfedgeHandle inner = plan.matched[e];
    return patch.is_boundary(h) ? mesh.opposite_halfedge_handle(inner) : inner;
  };
  for (const HalfedgeHandle h : patch.halfedges()) {
    if (patch.is_boundary(h)) continue;
    const HalfedgeHandle g = hmap(h);
    mesh.set_vertex_handle(
        g, VertexHandle(at.vmap[static_cast<std::size_t>(patch.to_vertex_handle(h).idx())]));
    mesh.set_face_handle(
        g, FaceHandle(at.fplace[static_cast<std::size_t>(patch.face_handle(h).idx())]));
    mesh.status(g) = OpenMesh::Attributes::StatusInfo();
    mesh.status(mesh.edge_handle(g)) = OpenMesh::Attributes::StatusInfo();
  }
  for (const HalfedgeHandle h : patch.halfedges())
    if (!patch.is_boundary(h))
      mesh.set_next_halfedge_handle(hmap(h), hmap(patch.next_halfedge_handle(h)));
  for (const FaceHandle f : patch.faces()) {
    const FaceHandle g(at.fplace[static_cast<std::size_t>(f.idx())]);
    mesh.set_halfedge_handle(g, hmap(patch.halfedge_handle(f)));
    mesh.status(g) = OpenMesh::Attributes::StatusInfo();
  }
  for (const VertexHandle v : patch.vertices()) {
    const VertexHandle w(at.vmap[static_cast<std::size_t>(v.idx())]);
    if (origin[static_cast<std::size_t>(v.idx())] < 0) {
      mesh.set_point(w, patch.point(v));
      mesh.status(w) = OpenMesh::Attributes::StatusInfo();
      mesh.set_halfedge_handle(w, hmap(patch.halfedge_handle(v)));
    } else {
      const HalfedgeHandle out = mesh.halfedge_handle(w);
      if (!out.is_valid() || plan.edge_gone[static_cast<std::size_t>(out.idx() / 2)])
        mesh.set_halfedge_handle(w, hmap(patch.halfedge_handle(v)));
    }
  }
}

// The new numbers of the mesh's and the patch's vertices and faces, from the owners of the first
// nv vertex and nf face places once close_gaps() has run.
SpliceMap splice_map(std::size_t old_vertices, std::size_t old_faces, const Mesh& patch,
                     const std::vector<int>& origin, const Placement& at, int nv, int nf) {
  SpliceMap map;
  map.vertices.assign(old_vertices, -1);
  map.faces.assign(old_faces, -1);
  map.patch_vertices.assign(patch.n_vertices(), -1);
  map.patch_faces.assign(patch.n_faces(), -1);
  for (int i = 0; i < nv; ++i) {
    const int o = at.vertex_owner[static_cast<std::size_t>(i)];
    if (o >= 0)
      map.vertices[static_cast<std::size_t>(o)] = i;
    else
      map.patch_vertices[static_cast<std::size_t>(
          at.new_vertices[static_cast<std::size_t>(-2 - o)])] = i;
  }
  for (std::size_t v = 0; v < origin.size(); ++v)
    if (origin[v] >= 0) map.patch_vertices[v] = map.vertices[static_cast<std::size_t>(origin[v])];
  for (int i = 0; i < nf; ++i) {
    const int o = at.face_owner[static_cast<std::size_t>(i)];
    if (o >= 0)
      map.faces[static_cast<std::size_t>(o)] = i;
    else
      map.patch_faces[static_cast<std::size_t>(-2 - o)] = i;
  }
  return map;
}

} // namespace

SpliceMap splice(Mesh& mesh, const std::vector<char>& removed, const Mesh& patch,
                 const std::vector<int>& origin) {
  const Plan plan = plan_splice(mesh, removed, patch, origin);
  const std::size_t old_vertices = mesh.n_vertices(), old_faces = mesh.n_faces();
  Placement at = place_patch(mesh, plan, patch, origin);
  write_patch(mesh, plan, patch, origin, at);
  // Places left over: the last elements move in.
  const int nv = close_gaps(at.vertex_owner, [&](int a, int b) { move_vertex(mesh, a, b); });
  const int ne = close_gaps(at.edge_owner, [&](int a, int b) { move_edge(mesh, a, b); });
  const int nf = close_gaps(at.face_owner, [&](int a, int b) { move_face(mesh, a, b); });
  mesh.resize(static_cast<std::size_t>(nv), static_cast<std::size_t>(ne),
              static_cast<std::size_t>(nf));
  return splice_map(old_vertices, old_faces, patch, origin, at, nv, nf);
}

} // namespace remora
