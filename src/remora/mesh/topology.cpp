#include "remora/mesh/topology.h"

#include <cstddef>
#include <string>
#include <utility>

#include "remora/common/error.h"

namespace remora {

Components connected_components(const Mesh& mesh) {
  Components result;
  result.vertex_component.assign(mesh.n_vertices(), -1);
  result.face_component.assign(mesh.n_faces(), -1);

  // Depth-first flood fill with an explicit stack; seeds are taken in increasing vertex index, so
  // component ids follow the smallest vertex index of each component.
  std::vector<VertexHandle> stack;
  for (const VertexHandle seed : mesh.vertices()) {
    if (result.vertex_component[seed.idx()] >= 0) continue;
    const int id = result.count++;
    result.vertex_component[seed.idx()] = id;
    stack.push_back(seed);
    while (!stack.empty()) {
      const VertexHandle v = stack.back();
      stack.pop_back();
      for (const HalfedgeHandle h : mesh.voh_range(v)) {
        const VertexHandle w = mesh.to_vertex_handle(h);
        if (result.vertex_component[w.idx()] < 0) {
          result.vertex_component[w.idx()] = id;
          stack.push_back(w);
        }
      }
    }
  }
  for (const FaceHandle f : mesh.faces()) {
    const VertexHandle v = mesh.to_vertex_handle(mesh.halfedge_handle(f));
    result.face_component[f.idx()] = result.vertex_component[v.idx()];
  }
  return result;
}

std::vector<std::vector<HalfedgeHandle>> boundary_loops(const Mesh& mesh) {
  std::vector<std::vector<HalfedgeHandle>> loops;
  std::vector<char> visited(mesh.n_halfedges(), 0);
  for (const HalfedgeHandle start : mesh.halfedges()) {
    if (visited[start.idx()] || !mesh.is_boundary(start)) continue;
    std::vector<HalfedgeHandle> loop;
    HalfedgeHandle h = start;
    do {
      if (visited[h.idx()] || !mesh.is_boundary(h) || mesh.status(h).deleted()) {
        throw Error("boundary_loops: corrupt connectivity: the boundary walk from halfedge " +
                    std::to_string(start.idx()) + " does not close at halfedge " +
                    std::to_string(h.idx()));
      }
      visited[h.idx()] = 1;
      loop.push_back(h);
      h = mesh.next_halfedge_handle(h);
    } while (h != start);
    loops.push_back(std::move(loop));
  }
  return loops;
}

std::vector<ComponentTopology> component_topology(const Mesh& mesh) {
  const Components components = connected_components(mesh);
  std::vector<ComponentTopology> result(static_cast<std::size_t>(components.count));
  for (const VertexHandle v : mesh.vertices()) {
    ++result[static_cast<std::size_t>(components.vertex_component[v.idx()])].vertices;
  }
  for (const EdgeHandle e : mesh.edges()) {
    const VertexHandle v = mesh.to_vertex_handle(mesh.halfedge_handle(e, 0));
    ++result[static_cast<std::size_t>(components.vertex_component[v.idx()])].edges;
  }
  for (const FaceHandle f : mesh.faces()) {
    ++result[static_cast<std::size_t>(components.face_component[f.idx()])].faces;
  }
  for (const std::vector<HalfedgeHandle>& loop : boundary_loops(mesh)) {
    const VertexHandle v = mesh.to_vertex_handle(loop.front());
    ++result[static_cast<std::size_t>(components.vertex_component[v.idx()])].boundary_loops;
  }
  for (ComponentTopology& c : result) {
    c.euler = c.vertices - c.edges + c.faces;
    // An isolated vertex (a point, euler 1) is not a surface; its genus is 0 by convention.
    c.genus = c.faces > 0 ? (2 - c.euler - c.boundary_loops) / 2 : 0;
    c.closed = c.faces > 0 && c.boundary_loops == 0;
  }
  return result;
}

} // namespace remora
