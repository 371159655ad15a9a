// bake(): the order of the local bake's steps (bake.h), the filter's band, the base's moved
// vertices, and the fallback to the full preprocess.
#include "remora/multires/bake.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <functional>
#include <future>
#include <queue>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/common/timer.h"
#include "remora/linalg/nested_dissection.h"
#include "remora/multires/bake_steps.h"
#include "remora/multires/phong.h"

namespace remora {

namespace bake_detail {
namespace {

// The input vertices whose point the edit changed (any coordinate, bitwise).
std::vector<int> changed_vertices(const Eigen::MatrixXd& before, const Eigen::MatrixXd& after) {
  std::vector<int> changed;
  for (Eigen::Index i = 0; i < before.rows(); ++i)
    if (before(i, 0) != after(i, 0) || before(i, 1) != after(i, 1) || before(i, 2) != after(i, 2))
      changed.push_back(static_cast<int>(i));
  return changed;
}

// Every vertex within `reach` of a source along the edges of the mesh (`points`), sorted:
// Dijkstra from all sources at once, over the faces around each vertex.
std::vector<int> grow_band(const TriangleTopology& t, const Eigen::MatrixXd& points,
                           const std::vector<int>& sources, double reach) {
  std::vector<double> distance(static_cast<std::size_t>(points.rows()),
                               std::numeric_limits<double>::infinity());
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (const int s : sources) {
    distance[static_cast<std::size_t>(s)] = 0.0;
    queue.emplace(0.0, s);
  }
  std::vector<int> band;
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > distance[static_cast<std::size_t>(v)]) continue;
    band.push_back(v);
    const auto vs = static_cast<std::size_t>(v);
    for (int k = t.vertex_offsets[vs]; k < t.vertex_offsets[vs + 1]; ++k)
      for (const int w :
           t.faces[static_cast<std::size_t>(t.vertex_faces[static_cast<std::size_t>(k)])]) {
        const double dw = d + (points.row(w) - points.row(v)).norm();
        if (dw <= reach && dw < distance[static_cast<std::size_t>(w)]) {
          distance[static_cast<std::size_t>(w)] = dw;
          queue.emplace(dw, w);
        }
      }
  }
  std::sort(band.begin(), band.end());
  return band;
}

// S' = S + F(O' − O), F solved on the band of settings.margin σ around the changed vertices.
void filter_band(Bake& b) {
  const auto n = static_cast<std::size_t>(b.input_positions.rows());
  b.in_band.assign(n, 0);
  b.smooth = b.old.smooth;
  const std::vector<int> changed = changed_vertices(b.old.input_positions, b.input_positions);
  b.report.changed_vertices = changed.size();
  if (changed.empty()) return;
  const double reach = b.settings.margin * b.old.filter->stats().sigma;
  const std::vector<int> band = grow_band(b.old.input_topology, b.input_positions, changed, reach);
  b.report.band_vertices = band.size();
  if (static_cast<double>(band.size()) > b.settings.max_fraction * static_cast<double>(n))
    throw NotLocal(
        fmt::format("the edit's band holds {} of the {} input vertices", band.size(), n));
  Eigen::MatrixXd change(static_cast<Eigen::Index>(band.size()), 3);
  for (std::size_t r = 0; r < band.size(); ++r)
    change.row(static_cast<Eigen::Index>(r)) =
        b.input_positions.row(band[r]) - b.old.input_positions.row(band[r]);
  const Eigen::MatrixXd smoothed = b.old.filter->apply_local(band, change);
  for (std::size_t r = 0; r < band.size(); ++r) {
    b.smooth.row(band[r]) += smoothed.row(static_cast<Eigen::Index>(r));
    b.in_band[static_cast<std::size_t>(band[r])] = 1;
  }
}

// B': every base vertex located on a face with a corner in the band goes to S' there.
void move_base(Bake& b) {
  const auto nb = static_cast<std::size_t>(b.old.base_rest.rows());
  b.base_points = b.old.base_rest;
  b.moved.assign(nb, 0);
  for (std::size_t v = 0; v < nb; ++v) {
    const SurfacePoint& sp = b.old.base_on_input[v];
    const auto& f = b.old.input_topology.faces[static_cast<std::size_t>(sp.face.idx())];
    if (!b.in_band[static_cast<std::size_t>(f[0])] && !b.in_band[static_cast<std::size_t>(f[1])] &&
        !b.in_band[static_cast<std::size_t>(f[2])])
      continue;
    b.base_points.row(static_cast<Eigen::Index>(v)) = sp.bary[0] * b.smooth.row(f[0]) +
                                                      sp.bary[1] * b.smooth.row(f[1]) +
                                                      sp.bary[2] * b.smooth.row(f[2]);
    b.moved[v] = 1;
    ++b.report.moved_base_vertices;
  }
}

// The old editor's Laplacian assembler carried over to the new base (linalg/kharmonic.h): per new
// base vertex its old vertex, and whether it is new (the patch's) or moved with S'.
void update_assembler(const Bake& b, const SpliceMap* map, EditorParts& parts) {
  const std::size_t n = parts.base.n_vertices();
  std::vector<int> previous_of(n, -1);
  std::vector<char> changed(n, 1);
  for (std::size_t o = 0; o < b.moved.size(); ++o) {
    const int v = map ? map->vertices[o] : static_cast<int>(o);
    if (v < 0) continue;
    previous_of[static_cast<std::size_t>(v)] = static_cast<int>(o);
    changed[static_cast<std::size_t>(v)] = b.moved[o];
  }
  if (map)
    for (const int v : map->patch_vertices) changed[static_cast<std::size_t>(v)] = 1;
  parts.assembler.emplace(parts.base, b.old.assembler, previous_of, changed, b.options.threads);
}

// The old base's nested-dissection order (Editor::prepare_regions) carried over: a vertex of the
// old base keeps its key (the order depends on the graph only, and moving a vertex keeps its
// edges), a patch vertex takes the key of the nearest one that has a key (breadth first). Where
// the patch crosses a separator of the order, the separator would no longer separate there:
// the rows that bridge it are raised into it (raise_to_common_ancestors() on the order's
// elimination tree), so that a region across the patch is still cut at the top of its tree
// (docs/solvers.md).
// Returns the milliseconds of the raise.
double carry_order(const Bake& b, const SpliceMap* map, EditorParts& parts) {
  if (b.old.base_order.empty()) return 0.0;
  const std::size_t n = parts.base.n_vertices();
  std::vector<int> keys(n, -1), queue;
  for (std::size_t o = 0; o < b.old.base_order.size(); ++o) {
    const int v = map ? map->vertices[o] : static_cast<int>(o);
    if (v < 0) continue;
    keys[static_cast<std::size_t>(v)] = b.old.base_order[o];
    queue.push_back(v);
  }
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const int v = queue[head];
    for (const VertexHandle w : parts.base.vv_range(VertexHandle(v)))
      if (keys[static_cast<std::size_t>(w.idx())] < 0) {
        keys[static_cast<std::size_t>(w.idx())] = keys[static_cast<std::size_t>(v)];
        queue.push_back(w.idx());
      }
  }
  for (int& k : keys) k = std::max(k, 0); // a component with no old vertex
  // Where the patch crossed a separator, its rows go up to the separator they bridge (without a
  // patch the graph is the old one).
  parts.base_order_tree = b.old.base_order_tree;
  const auto t0 = Clock::now();
  if (map && !parts.base_order_tree.empty()) try {
      raise_to_common_ancestors(parts.assembler->minus_w(), b.old.base_order_k,
                                parts.base_order_tree, keys);
    } catch (const InvalidArgument&) {
      parts.base_order_tree.clear(); // not the old order's tree: the keys stay as carried
    }
  parts.base_order = std::move(keys);
  parts.base_order_k = b.old.base_order_k;
  return ms_since(t0);
}

// B's vertex normals: the old ones renumbered, and measured again (update_vertex_normals(), the
// same bits as vertex_normals()) around every face that is new, has a moved corner or changed
// its index, which could change the order of a vertex's faces and so its sum.
void carry_normals(const Bake& b, const SpliceMap* map, EditorParts& parts) {
  const auto n = static_cast<Eigen::Index>(parts.base.n_vertices());
  parts.base_normals.resize(n, 3);
  for (std::size_t o = 0; o < b.moved.size(); ++o) {
    const int v = map ? map->vertices[o] : static_cast<int>(o);
    if (v >= 0) parts.base_normals.row(v) = b.old.base_normals.row(static_cast<Eigen::Index>(o));
  }
  std::vector<char> touched(static_cast<std::size_t>(n), 0);
  const auto touch = [&](int f) {
    for (const int v : parts.topology.faces[static_cast<std::size_t>(f)])
      touched[static_cast<std::size_t>(v)] = 1;
  };
  if (map)
    for (const int f : map->patch_faces) touch(f);
  const TriangleTopology& old = b.old.topology;
  for (std::size_t f = 0; f < old.faces.size(); ++f) {
    const int to = map ? map->faces[f] : static_cast<int>(f);
    if (to < 0) continue;
    const auto& c = old.faces[f];
    if (to != static_cast<int>(f) || b.moved[static_cast<std::size_t>(c[0])] ||
        b.moved[static_cast<std::size_t>(c[1])] || b.moved[static_cast<std::size_t>(c[2])])
      touch(to);
  }
  std::vector<int> vertices;
  for (std::size_t v = 0; v < touched.size(); ++v)
    if (touched[v]) vertices.push_back(static_cast<int>(v));
  update_vertex_normals(parts.topology, parts.base_rest, vertices, parts.base_normals,
                        b.options.threads);
}

// The process's CPU time in milliseconds.
double cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

// Runs f, adding its wall and CPU time to the report's part.
template <class F>
auto timed(BakeReport& report, const char* part, F&& f) {
  struct Stop {
    BakeReport& report;
    const char* part;
    Clock::time_point t0 = Clock::now();
    double cpu0 = cpu_ms();
    ~Stop() {
      report.milliseconds[part] += ms_since(t0);
      report.cpu_milliseconds[part] += cpu_ms() - cpu0;
    }
  } stop{report, part};
  return f();
}

// The steps after the splice, on two threads. The second updates the old editor's assembler to
// the new base, carries the base's order over (raising it where the patch crossed a separator),
// then the base's vertex statistics and the figures over them from it; it reads the old editor,
// the new base and the map, and writes parts.assembler, parts.base_order, parts.base_order_tree
// and parts.statistics, which the first thread does not read. The first copies the input, mends
// the correspondence and updates the other figures and the normals. "assembler" is the second
// thread's wall time, "order raise" the raise within it, "wait" the first's wait for it (with one
// thread the second's work runs inside "wait"). Should the first thread throw, the future's
// destructor waits for the job, which reads only what outlives it.
void finish(Bake& b, const PatchMeshes* meshes, const RemeshPatchResult* remeshed,
            const SpliceMap* map, EditorParts& parts) {
  const BaseChange change = timed(b.report, "report", [&] { return base_change(b, map); });
  double assembler_ms = 0, raise_ms = 0;
  VertexFigures figures;
  auto job = std::async(b.options.threads == 1 ? std::launch::deferred : std::launch::async, [&] {
    const auto t0 = Clock::now();
    update_assembler(b, map, parts);
    raise_ms = carry_order(b, map, parts);
    figures = update_vertex_figures(b.old.statistics, parts.base, change, *parts.assembler,
                                    parts.statistics, b.options.threads);
    assembler_ms = ms_since(t0);
  });
  timed(b.report, "mend", [&] {
    carry_input(b, parts);
    mend(b, meshes, remeshed, map, parts);
  });
  timed(b.report, "report", [&] { base_figures(b, change, parts, map); });
  timed(b.report, "normals", [&] { carry_normals(b, map, parts); });
  timed(b.report, "wait", [&] { job.get(); });
  parts.report.base_quality.mixed_area = figures.mixed_area;
  parts.report.base_quality.barycentric_area = figures.barycentric_area;
  parts.report.base_symmetry_defect = figures.symmetry_defect;
  b.report.milliseconds["assembler"] = assembler_ms;
  if (!b.old.base_order.empty()) b.report.milliseconds["order raise"] = raise_ms;
}

// Step 3's splice and finish().
void stitch_and_finish(Bake& b, const PatchMeshes* meshes, const RemeshPatchResult* remeshed,
                       SpliceMap& map, EditorParts& parts) {
  timed(b.report, "stitch", [&] { stitch(b, meshes, remeshed, map, parts); });
  finish(b, meshes, remeshed, meshes ? &map : nullptr, parts);
}

// Steps 1-3 of bake.h into `parts` (an empty EditorParts, where the new editor keeps it); throws
// NotLocal (or what a step throws) where they cannot work.
void local_parts(const Editor& editor, const Eigen::MatrixXd& positions,
                 const BakeOptions& settings, BakeReport& report, EditorParts& parts) {
  const EditorOptions& options = editor.options();
  Bake b{editor.parts(), options, settings, report, positions, {}, {}, {}, {}, {}};
  auto progress = [&](int step) {
    if (options.progress) options.progress("bake", step, 4);
  };
  progress(0);
  timed(report, "filter", [&] { filter_band(b); });
  timed(report, "base", [&] { move_base(b); });
  progress(1);
  SpliceMap map;
  const bool has_patch = timed(report, "patch", [&] { return select_patch(b); });
  if (!has_patch) {
    stitch_and_finish(b, nullptr, nullptr, map, parts);
    return;
  }
  const PatchMeshes meshes = timed(report, "patch", [&] { return patch_meshes(b); });
  progress(2);
  RemeshOptions ro = options.remesh_options;
  ro.target_length = b.old.report.base_target_length;
  ro.threads = options.threads;
  ro.compute_report = false;
  ro.cycles = settings.cycles;
  ro.equalize_iterations = settings.equalize_iterations;
  ro.progress = nullptr;
  const RemeshPatchResult remeshed =
      timed(report, "remesh", [&] { return remesh_patch(meshes.reference, meshes.patch, ro); });
  report.patch_faces_after = remeshed.mesh.n_faces();
  progress(3);
  stitch_and_finish(b, &meshes, &remeshed, map, parts);
}

} // namespace

// The new editor prepared for regions (Editor::prepare_regions) when the old one was: its rows
// computed, its order carried over (carry_order) or, after a full re-preprocess, computed.
void prepare_like(const Editor& old, Editor& baked, BakeReport& report) {
  const EditorPartsView p = old.parts();
  if (p.assembler.kept_row_bytes() == 0 && p.base_order.empty()) return;
  const auto t0 = Clock::now();
  baked.prepare_regions();
  report.milliseconds["prepare regions"] = ms_since(t0);
}

} // namespace bake_detail

BakeResult bake(Editor& editor, const BakeOptions& options) {
  const auto t0 = Clock::now();
  const Eigen::MatrixXd& positions = editor.positions();
  BakeReport report;
  std::string reason;
  if (options.force_full)
    reason = "asked for";
  else if (!editor.options().remesh)
    reason = "the base is the input itself (no remesh)";
  else if (editor.options().remesh_options.feature_angle_deg > 0)
    reason = "the base keeps feature lines";
  if (reason.empty()) {
    try {
      const double cpu0 = bake_detail::cpu_ms();
      Clock::time_point built;
      Editor baked(
          [&](EditorParts& parts) {
            bake_detail::local_parts(editor, positions, options, report, parts);
            built = Clock::now();
          },
          editor.options());
      report.milliseconds["editor"] = ms_since(built);
      bake_detail::prepare_like(editor, baked, report);
      report.cpu_milliseconds["total"] = bake_detail::cpu_ms() - cpu0;
      report.local = true;
      report.milliseconds["total"] = ms_since(t0);
      return {std::move(baked), std::move(report)};
    } catch (const bake_detail::NotLocal& e) {
      reason = e.what();
    } catch (const Error& e) {
      reason = fmt::format("the local bake failed: {}", e.what());
    }
  }
  BakeReport full;
  full.fallback = reason;
  full.changed_vertices = report.changed_vertices;
  Editor baked(editor.result(), editor.options());
  bake_detail::prepare_like(editor, baked, full);
  full.milliseconds["total"] = ms_since(t0);
  return {std::move(baked), std::move(full)};
}

} // namespace remora
