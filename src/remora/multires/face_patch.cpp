// A patch of a triangle mesh's faces (face_patch.h).
#include "remora/multires/face_patch.h"

#include "remora/mesh/build.h"

namespace remora {

namespace {

// How many separate runs of marked faces lie around v (its faces in turn; a boundary gap is
// unmarked): more than one makes v a pinch of the marked part.
int fan_runs(const Mesh& mesh, VertexHandle v, const std::vector<char>& in) {
  int runs = 0;
  bool first = false, last = false, start = true;
  for (const HalfedgeHandle h : mesh.voh_range(v)) {
    const FaceHandle f = mesh.face_handle(h);
    const bool marked = f.is_valid() && in[static_cast<std::size_t>(f.idx())];
    if (start) first = marked;
    if (marked && !last && !start) ++runs;
    last = marked;
    start = false;
  }
  if (first && !last) ++runs; // a run that starts with the turn (all marked: no start, 0)
  return runs;
}

} // namespace

void add_fan(const TriangleTopology& t, int v, std::vector<char>& in, std::vector<int>& faces) {
  const auto vs = static_cast<std::size_t>(v);
  for (int k = t.vertex_offsets[vs]; k < t.vertex_offsets[vs + 1]; ++k) {
    const int f = t.vertex_faces[static_cast<std::size_t>(k)];
    if (!in[static_cast<std::size_t>(f)]) {
      in[static_cast<std::size_t>(f)] = 1;
      faces.push_back(f);
    }
  }
}

void grow_rings(const TriangleTopology& t, int rings, std::vector<char>& in,
                std::vector<int>& faces) {
  std::vector<char> done(t.vertex_offsets.size() - 1, 0);
  for (int ring = 0; ring < rings; ++ring) {
    const std::size_t end = faces.size();
    for (std::size_t i = 0; i < end; ++i)
      for (const int v : t.faces[static_cast<std::size_t>(faces[i])]) {
        if (done[static_cast<std::size_t>(v)]) continue;
        done[static_cast<std::size_t>(v)] = 1;
        add_fan(t, v, in, faces);
      }
  }
}

// A worklist of the vertices whose faces changed, until it is empty.
void close_patch(const Mesh& mesh, const TriangleTopology& t, bool bridges, std::vector<char>& in,
                 std::vector<int>& faces) {
  std::vector<char> vertex(t.vertex_offsets.size() - 1, 0), queued(vertex.size(), 0);
  std::vector<int> work;
  auto touch = [&](int f) {
    for (const int v : t.faces[static_cast<std::size_t>(f)]) {
      vertex[static_cast<std::size_t>(v)] = 1;
      if (!queued[static_cast<std::size_t>(v)]) {
        queued[static_cast<std::size_t>(v)] = 1;
        work.push_back(v);
      }
    }
  };
  auto add = [&](int f) {
    if (f < 0 || in[static_cast<std::size_t>(f)]) return;
    in[static_cast<std::size_t>(f)] = 1;
    faces.push_back(f);
    touch(f);
  };
  for (const int f : faces) touch(f);
  while (!work.empty()) {
    const int v = work.back();
    work.pop_back();
    queued[static_cast<std::size_t>(v)] = 0;
    const auto vs = static_cast<std::size_t>(v);
    const int begin = t.vertex_offsets[vs], end = t.vertex_offsets[vs + 1];
    if (fan_runs(mesh, VertexHandle(v), in) > 1) {
      for (int k = begin; k < end; ++k) add(t.vertex_faces[static_cast<std::size_t>(k)]);
      continue;
    }
    if (!bridges) continue;
    for (int k = begin; k < end; ++k) {
      const int g = t.vertex_faces[static_cast<std::size_t>(k)];
      if (in[static_cast<std::size_t>(g)]) continue;
      const auto& gv = t.faces[static_cast<std::size_t>(g)];
      for (std::size_t c = 0; c < 3; ++c) {
        const int h = t.across[static_cast<std::size_t>(g)][c];
        if (vertex[static_cast<std::size_t>(gv[(c + 1) % 3])] &&
            vertex[static_cast<std::size_t>(gv[(c + 2) % 3])] &&
            (h < 0 || !in[static_cast<std::size_t>(h)])) {
          add(g);
          add(h);
          break;
        }
      }
    }
  }
}

Mesh sub_mesh(const TriangleTopology& t, const Eigen::MatrixXd& points,
              const std::vector<int>& faces, std::vector<int>& local, std::vector<int>& vertices) {
  std::vector<std::array<std::uint32_t, 3>> triangles(faces.size());
  std::vector<Vec3> at;
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const int v = t.faces[static_cast<std::size_t>(faces[i])][static_cast<std::size_t>(k)];
      int& l = local[static_cast<std::size_t>(v)];
      if (l < 0) {
        l = static_cast<int>(vertices.size());
        vertices.push_back(v);
        at.emplace_back(points(v, 0), points(v, 1), points(v, 2));
      }
      triangles[i][static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(l);
    }
  return build_mesh(at, triangles);
}

} // namespace remora
