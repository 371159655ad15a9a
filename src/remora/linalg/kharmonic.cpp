#include "remora/linalg/kharmonic.h"

#include <algorithm>
#include <future>
#include <limits>
#include <memory>
#include <numeric>
#include <string>

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"
#include "remora/mesh/topology.h"

namespace remora {

// Named, not anonymous: KHarmonicAssembler::KeptRows holds it (GCC's -Wsubobject-linkage in unity
// builds).
namespace kharmonic_detail {

// Rows of the system, as (vertex, value) lists in vertex order without the zero sums: row i's
// entries are [start[i], start[i + 1]).
struct RowBlock {
  std::vector<int> start{0}, vertex;
  std::vector<double> value;
};

} // namespace kharmonic_detail

using kharmonic_detail::RowBlock;

struct KHarmonicAssembler::KeptRows {
  int k = 0;
  bool scaled = false; // the inner areas S = A⁻¹ (MixedSymmetric, Mixed) or none (Mean)
  RowBlock rows;       // row v is vertex v's, without the Mixed system's row scaling
};

namespace {

using RowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

void validate_labels(std::size_t n, const Region& region, const KHarmonicOptions& options) {
  if (options.k < 1 || options.k > 3)
    throw InvalidArgument("k-harmonic system: k = " + std::to_string(options.k) +
                          " is not supported; use 1, 2 or 3");
  if (region.label.size() != n)
    throw InvalidArgument("k-harmonic system: the region has " +
                          std::to_string(region.label.size()) + " labels for a mesh of " +
                          std::to_string(n) + " vertices; give one per vertex");
  for (std::size_t i = 0; i < n; ++i)
    if (region.label[i] < Region::kFixed)
      throw InvalidArgument("k-harmonic system: vertex " + std::to_string(i) + " has label " +
                            std::to_string(region.label[i]) +
                            "; use -1 (free), -2 (fixed) or a handle index >= 0");
  if (region.free_count() == 0)
    throw InvalidArgument("k-harmonic system: no vertex is free; the support is empty");
}

// Numbers the free vertices in vertex order: system.free_vertices and system.row_of (-1 for a
// vertex that is not free).
void number_free_vertices(const Region& region, KHarmonicSystem& system) {
  const std::size_t n = region.label.size();
  system.row_of.assign(n, -1);
  for (std::size_t v = 0; v < n; ++v)
    if (region.label[v] == Region::kFree) {
      system.row_of[v] = static_cast<int>(system.free_vertices.size());
      system.free_vertices.push_back(static_cast<int>(v));
    }
}

// A row of a sparse product being accumulated: values by vertex, and the vertices touched.
struct Accumulator {
  explicit Accumulator(std::size_t n) : value(n), seen(n, 0) {}
  std::vector<double> value;
  std::vector<char> seen;
  std::vector<int> touched;
  void add(int j, double x) {
    const auto u = static_cast<std::size_t>(j);
    if (!seen[u]) {
      seen[u] = 1;
      value[u] = 0.0;
      touched.push_back(j);
    }
    value[u] += x;
  }
  void clear() {
    for (const int j : touched) seen[static_cast<std::size_t>(j)] = 0;
    touched.clear();
  }
};

// Row v of (−W)(S(−W))^(k−1), S = diag(scale) (null: the identity), accumulated into `out`. Each
// term is (a_vm a_mj) s_m, summed in increasing m, so that for k <= 2 the entries (v, j) and
// (j, v) are the same sums of the same products: symmetric bit for bit.
void power_row(const SparseMatrix& minus_w, const Eigen::VectorXd* scale, int k, int v,
               Accumulator& inner, Accumulator& out) {
  const auto column = [&](int c, auto&& f) {
    for (SparseMatrix::InnerIterator it(minus_w, c); it; ++it)
      f(static_cast<int>(it.row()), it.value());
  };
  const auto s = [&](int m) { return scale ? (*scale)[m] : 1.0; };
  if (k == 1) {
    column(v, [&](int j, double a) { out.add(j, a); });
    return;
  }
  Accumulator& second = k == 2 ? out : inner;
  column(v, [&](int m, double a) {
    const double sm = s(m);
    column(m, [&](int j, double b) { second.add(j, a * b * sm); });
  });
  if (k == 2) return;
  std::sort(inner.touched.begin(), inner.touched.end());
  for (const int m : inner.touched) {
    const double r = inner.value[static_cast<std::size_t>(m)], sm = s(m);
    column(m, [&](int j, double b) { out.add(j, r * b * sm); });
  }
  inner.clear();
}

RowBlock power_rows(const SparseMatrix& minus_w, const Eigen::VectorXd* scale, int k,
                    const Eigen::VectorXd* mixed_scale, const std::vector<int>& free_vertices,
                    std::size_t begin, std::size_t end) {
  const auto n = static_cast<std::size_t>(minus_w.rows());
  Accumulator inner(k == 3 ? n : 0), out(n);
  RowBlock block;
  for (std::size_t r = begin; r < end; ++r) {
    const int v = free_vertices[r];
    power_row(minus_w, scale, k, v, inner, out);
    std::sort(out.touched.begin(), out.touched.end());
    const double row_scale = mixed_scale ? (*mixed_scale)[v] : 1.0;
    for (const int j : out.touched) {
      const double x = out.value[static_cast<std::size_t>(j)];
      if (x == 0.0) continue;
      block.vertex.push_back(j);
      block.value.push_back(mixed_scale ? x * row_scale : x);
    }
    out.clear();
    block.start.push_back(static_cast<int>(block.vertex.size()));
  }
  return block;
}

// The rows of `vertices` (in that order) as blocks of consecutive rows, built on `threads`
// threads; `mixed_scale` scales each row by its vertex's inverse area (the Mixed system).
std::vector<RowBlock> power_rows_in_blocks(const SparseMatrix& minus_w, int threads,
                                           const std::vector<int>& vertices,
                                           const Eigen::VectorXd* scale, int k,
                                           const Eigen::VectorXd* mixed_scale) {
  const std::size_t count_rows = vertices.size();
  const int team = threads > 0 ? threads : omp_get_max_threads();
  const std::size_t count = count_rows < 4096 ? 1 : static_cast<std::size_t>(4 * team);
  std::vector<RowBlock> blocks(count);
  parallel_blocks(count, threads, [&](std::size_t b) {
    blocks[b] = power_rows(minus_w, scale, k, mixed_scale, vertices, b * count_rows / count,
                           (b + 1) * count_rows / count);
  });
  return blocks;
}

// A free row as the split reads it: its entries (vertex, value) in vertex order, each value
// multiplied by `scale` (the Mixed system's inverse area when the row was kept unscaled).
struct RowView {
  const int* vertex;
  const double* value;
  int size;
  double scale;
};

// Splits the rows by column into system.matrix (free columns, by row_of) and system.coupling
// (constrained columns, numbered in vertex order into system.constrained_vertices): the rows
// counted and filled on `threads` threads.
void split_columns(const std::vector<RowView>& rows, std::size_t n, KHarmonicSystem& system,
                   int threads) {
  std::vector<int> column_of(n, -1);
  for (const RowView& row : rows)
    for (int e = 0; e < row.size; ++e)
      if (system.row_of[static_cast<std::size_t>(row.vertex[e])] < 0)
        column_of[static_cast<std::size_t>(row.vertex[e])] = 0;
  for (std::size_t v = 0; v < n; ++v)
    if (column_of[v] >= 0) {
      column_of[v] = static_cast<int>(system.constrained_vertices.size());
      system.constrained_vertices.push_back(static_cast<int>(v));
    }
  const std::size_t nf = rows.size();
  std::vector<int> free_start(nf + 1, 0), constrained_start(nf + 1, 0);
  parallel_for_static(nf, threads, [&](std::size_t r) {
    int free = 0;
    for (int e = 0; e < rows[r].size; ++e)
      free += system.row_of[static_cast<std::size_t>(rows[r].vertex[e])] >= 0;
    free_start[r + 1] = free;
    constrained_start[r + 1] = rows[r].size - free;
  });
  for (std::size_t r = 0; r < nf; ++r) {
    free_start[r + 1] += free_start[r];
    constrained_start[r + 1] += constrained_start[r];
  }
  // Both numberings follow the vertex order, so each row's entries come out sorted.
  std::vector<int> free_column(static_cast<std::size_t>(free_start[nf])),
      constrained_column(static_cast<std::size_t>(constrained_start[nf]));
  std::vector<double> free_value(free_column.size()), constrained_value(constrained_column.size());
  parallel_for_static(nf, threads, [&](std::size_t r) {
    const RowView& row = rows[r];
    auto f = static_cast<std::size_t>(free_start[r]),
         c = static_cast<std::size_t>(constrained_start[r]);
    for (int e = 0; e < row.size; ++e) {
      const auto j = static_cast<std::size_t>(row.vertex[e]);
      const double x = row.scale == 1.0 ? row.value[e] : row.value[e] * row.scale;
      if (system.row_of[j] >= 0) {
        free_column[f] = system.row_of[j];
        free_value[f++] = x;
      } else {
        constrained_column[c] = column_of[j];
        constrained_value[c++] = x;
      }
    }
  });
  const auto rows_count = static_cast<Eigen::Index>(nf);
  const auto nc = static_cast<Eigen::Index>(system.constrained_vertices.size());
  // A symmetric matrix is its own transpose: its row-major arrays are its column-major ones.
  if (system.symmetric) {
    system.matrix = Eigen::Map<const SparseMatrix>(
        rows_count, rows_count, static_cast<Eigen::Index>(free_value.size()), free_start.data(),
        free_column.data(), free_value.data());
  } else {
    system.matrix = Eigen::Map<const RowMatrix>(
        rows_count, rows_count, static_cast<Eigen::Index>(free_value.size()), free_start.data(),
        free_column.data(), free_value.data());
  }
  const Eigen::Map<const RowMatrix> coupling(
      rows_count, nc, static_cast<Eigen::Index>(constrained_value.size()), constrained_start.data(),
      constrained_column.data(), constrained_value.data());
  system.coupling = coupling;
}

} // namespace

KHarmonicAssembler::KHarmonicAssembler(const Mesh& mesh, int threads) : threads_(threads) {
  // −W on this thread; the areas, the adjacency and its components on another (each part is
  // mostly a sequential pass over the mesh); one thread when `threads` is 1.
  auto rest = std::async(threads == 1 ? std::launch::deferred : std::launch::async,
                         [&] { areas_and_adjacency(mesh); });
  minus_w_ = cotan_weights(mesh);
  minus_w_.makeCompressed();
  minus_w_.coeffs() = -minus_w_.coeffs();
  rest.get();
}

void KHarmonicAssembler::areas_and_adjacency(const Mesh& mesh) {
  area_ = vertex_areas_mixed(mesh);
  inverse_areas();
  const std::size_t n = mesh.n_vertices();
  offsets_.assign(n + 1, 0);
  for (const VertexHandle v : mesh.vertices()) {
    for (const VertexHandle w : mesh.vv_range(v)) adjacent_.push_back(w.idx());
    offsets_[static_cast<std::size_t>(v.idx()) + 1] = static_cast<int>(adjacent_.size());
  }
  for (std::size_t v = 0; v < n; ++v) offsets_[v + 1] = std::max(offsets_[v + 1], offsets_[v]);
  find_components(mesh);
}

// The inverse vertex areas of the inner factors: 1 / mixed area, floored at 1e-12 times the mean
// positive area. A vertex whose faces all have zero area (needles of a raw scan) gets a floor
// instead of an infinite inverse; its row of W is zero anyway.
void KHarmonicAssembler::inverse_areas() {
  const Eigen::Index n = area_.size();
  double mean = 0;
  Eigen::Index counted = 0;
  for (Eigen::Index v = 0; v < n; ++v)
    if (area_[v] > 0) {
      mean += area_[v];
      ++counted;
    }
  mean = counted > 0 ? mean / static_cast<double>(counted) : 1.0;
  inverse_area_.resize(n);
  for (Eigen::Index v = 0; v < n; ++v) inverse_area_[v] = 1.0 / std::max(area_[v], 1e-12 * mean);
}

// The connected components of the adjacency, numbered in the order of their smallest vertex (as
// connected_components() numbers them); -1 for a deleted vertex.
void KHarmonicAssembler::find_components(const Mesh& mesh) {
  const std::size_t n = mesh.n_vertices();
  component_.assign(n, -1);
  components_ = 0;
  std::vector<int> stack;
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (component_[seed] >= 0 || mesh.status(VertexHandle(static_cast<int>(seed))).deleted())
      continue;
    component_[seed] = components_;
    stack.push_back(static_cast<int>(seed));
    while (!stack.empty()) {
      const auto v = static_cast<std::size_t>(stack.back());
      stack.pop_back();
      for (int a = offsets_[v]; a < offsets_[v + 1]; ++a) {
        const auto w = static_cast<std::size_t>(adjacent_[static_cast<std::size_t>(a)]);
        if (component_[w] < 0) component_[w] = components_, stack.push_back(static_cast<int>(w));
      }
    }
    ++components_;
  }
}

KHarmonicSystem KHarmonicAssembler::assemble(const Region& region,
                                             const KHarmonicOptions& options) const {
  const std::size_t n = vertex_count();
  validate_labels(n, region, options);
  check_handles_and_components(region);
  KHarmonicSystem system;
  system.symmetric = options.areas != AreaWeights::Mixed;
  number_free_vertices(region, system);
  const Eigen::VectorXd* scale = options.areas == AreaWeights::Mean ? nullptr : &inverse_area_;
  const Eigen::VectorXd* mixed = options.areas == AreaWeights::Mixed ? &inverse_area_ : nullptr;
  const std::size_t nf = system.free_vertices.size();
  std::vector<RowView> rows(nf);
  std::vector<RowBlock> blocks;
  if (kept_ && kept_->k == options.k && kept_->scaled == (scale != nullptr)) {
    const RowBlock& all = kept_->rows; // row v is vertex v's, unscaled for Mixed
    parallel_for_static(nf, threads_, [&](std::size_t r) {
      const auto v = static_cast<std::size_t>(system.free_vertices[r]);
      const int begin = all.start[v];
      rows[r] = {all.vertex.data() + begin, all.value.data() + begin, all.start[v + 1] - begin,
                 mixed ? (*mixed)[static_cast<Eigen::Index>(v)] : 1.0};
    });
  } else {
    blocks =
        power_rows_in_blocks(minus_w_, threads_, system.free_vertices, scale, options.k, mixed);
    for (std::size_t b = 0, r = 0; b < blocks.size(); ++b)
      for (std::size_t i = 0; i + 1 < blocks[b].start.size(); ++i, ++r)
        rows[r] = {blocks[b].vertex.data() + blocks[b].start[i],
                   blocks[b].value.data() + blocks[b].start[i],
                   blocks[b].start[i + 1] - blocks[b].start[i], 1.0};
  }
  split_columns(rows, n, system, threads_);
  if (system.symmetric && options.k == 3) {
    // k = 3 sums its products in another order for (i, j) than for (j, i): symmetric to
    // round-off only.
    const SparseMatrix transposed = system.matrix.transpose();
    system.matrix = 0.5 * (system.matrix + transposed);
  }
  system.matrix.makeCompressed();
  system.coupling.makeCompressed();
  return system;
}

void KHarmonicAssembler::keep_rows(const KHarmonicOptions& options) {
  if (options.k < 1 || options.k > 3)
    throw InvalidArgument("k-harmonic rows: k = " + std::to_string(options.k) +
                          " is not supported; use 1, 2 or 3");
  const bool scaled = options.areas != AreaWeights::Mean;
  if (kept_ && kept_->k == options.k && kept_->scaled == scaled) return;
  std::vector<int> all(vertex_count());
  std::iota(all.begin(), all.end(), 0);
  const std::vector<RowBlock> blocks = power_rows_in_blocks(
      minus_w_, threads_, all, scaled ? &inverse_area_ : nullptr, options.k, nullptr);
  auto kept = std::make_shared<KeptRows>();
  kept->k = options.k;
  kept->scaled = scaled;
  RowBlock& rows = kept->rows;
  std::size_t entries = 0;
  for (const RowBlock& b : blocks) entries += b.vertex.size();
  if (entries > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw InvalidArgument("k-harmonic rows: " + std::to_string(entries) +
                          " entries are more than 32-bit offsets hold; assemble each region");
  rows.start.reserve(vertex_count() + 1);
  rows.vertex.reserve(entries);
  rows.value.reserve(entries);
  for (const RowBlock& b : blocks) {
    const int shift = rows.start.back();
    for (std::size_t i = 1; i < b.start.size(); ++i) rows.start.push_back(b.start[i] + shift);
    rows.vertex.insert(rows.vertex.end(), b.vertex.begin(), b.vertex.end());
    rows.value.insert(rows.value.end(), b.value.begin(), b.value.end());
  }
  kept_ = std::move(kept);
}

std::size_t KHarmonicAssembler::kept_row_bytes() const {
  if (!kept_) return 0;
  return kept_->rows.start.size() * sizeof(int) +
         kept_->rows.vertex.size() * (sizeof(int) + sizeof(double));
}

int Region::handle_count() const {
  int h = 0;
  for (int l : label) h = std::max(h, l + 1);
  return h;
}

std::size_t Region::free_count() const {
  return static_cast<std::size_t>(std::count(label.begin(), label.end(), kFree));
}

std::string to_string(AreaWeights weights) {
  switch (weights) {
  case AreaWeights::Mixed:
    return "mixed";
  case AreaWeights::Mean:
    return "mean";
  case AreaWeights::MixedSymmetric:
    return "mixed-symmetric";
  }
  return "?";
}

AreaWeights parse_area_weights(const std::string& name) {
  if (name == "mixed") return AreaWeights::Mixed;
  if (name == "mean") return AreaWeights::Mean;
  if (name == "mixed-symmetric") return AreaWeights::MixedSymmetric;
  throw InvalidArgument("unknown area weighting '" + name +
                        "'; use mixed, mean or mixed-symmetric");
}

Eigen::MatrixXd KHarmonicSystem::rhs(const Eigen::MatrixXd& constrained_values) const {
  if (constrained_values.rows() != coupling.cols())
    throw InvalidArgument("k-harmonic system: " + std::to_string(constrained_values.rows()) +
                          " constrained values given for " + std::to_string(coupling.cols()) +
                          " constrained vertices");
  return -(coupling * constrained_values);
}

Eigen::MatrixXd KHarmonicSystem::gather_constrained(const Eigen::MatrixXd& positions) const {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(constrained_vertices.size()), positions.cols());
  for (std::size_t c = 0; c < constrained_vertices.size(); ++c)
    out.row(static_cast<Eigen::Index>(c)) = positions.row(constrained_vertices[c]);
  return out;
}

// Every handle has a vertex and touches a free vertex; every component with a free vertex has a
// constrained one.
void KHarmonicAssembler::check_handles_and_components(const Region& region) const {
  const std::size_t n = vertex_count();
  const int handles = region.handle_count();
  std::vector<char> has_vertex(static_cast<std::size_t>(handles), 0),
      touches_free(static_cast<std::size_t>(handles), 0);
  for (std::size_t v = 0; v < n; ++v) {
    const int j = region.label[v];
    if (j < 0 || component_[v] < 0) continue;
    has_vertex[static_cast<std::size_t>(j)] = 1;
    for (int e = offsets_[v]; e < offsets_[v + 1]; ++e)
      if (region.label[static_cast<std::size_t>(adjacent_[static_cast<std::size_t>(e)])] ==
          Region::kFree)
        touches_free[static_cast<std::size_t>(j)] = 1;
  }
  for (int j = 0; j < handles; ++j) {
    if (!has_vertex[static_cast<std::size_t>(j)])
      throw InvalidArgument("k-harmonic system: handle " + std::to_string(j) +
                            " has no vertex (handles are numbered 0.." +
                            std::to_string(handles - 1) + " without gaps)");
    if (!touches_free[static_cast<std::size_t>(j)])
      throw InvalidArgument("k-harmonic system: handle " + std::to_string(j) +
                            " touches no free vertex, so moving it would move nothing; put it "
                            "inside or next to the support");
  }
  std::vector<int> free_witness(static_cast<std::size_t>(components_), -1);
  std::vector<char> constrained(static_cast<std::size_t>(components_), 0);
  for (std::size_t v = 0; v < n; ++v) {
    const int c = component_[v];
    if (c < 0) continue;
    if (region.label[v] == Region::kFree) {
      if (free_witness[static_cast<std::size_t>(c)] < 0)
        free_witness[static_cast<std::size_t>(c)] = static_cast<int>(v);
    } else {
      constrained[static_cast<std::size_t>(c)] = 1;
    }
  }
  for (int c = 0; c < components_; ++c)
    if (free_witness[static_cast<std::size_t>(c)] >= 0 && !constrained[static_cast<std::size_t>(c)])
      throw InvalidArgument(
          "k-harmonic system: the support covers a whole connected component of the mesh (the "
          "one with vertex " +
          std::to_string(free_witness[static_cast<std::size_t>(c)]) +
          ") with no fixed or handle vertex, so its position is undetermined; fix at least one "
          "vertex of that component or make the support smaller");
}

KHarmonicSystem assemble_kharmonic(const Mesh& mesh, const Region& region,
                                   const KHarmonicOptions& options) {
  return KHarmonicAssembler(mesh).assemble(region, options);
}

Eigen::MatrixXd positions_matrix(const Mesh& mesh) {
  Eigen::MatrixXd p(static_cast<Eigen::Index>(mesh.n_vertices()), 3);
  for (auto v : mesh.all_vertices()) {
    const Vec3& q = mesh.point(v);
    p.row(v.idx()) << q[0], q[1], q[2];
  }
  return p;
}

void set_positions(Mesh& mesh, const Eigen::MatrixXd& positions) {
  if (positions.rows() != static_cast<Eigen::Index>(mesh.n_vertices()) || positions.cols() != 3)
    throw InvalidArgument("set_positions: " + std::to_string(positions.rows()) + " x " +
                          std::to_string(positions.cols()) + " positions for a mesh of " +
                          std::to_string(mesh.n_vertices()) + " vertices (n x 3 expected)");
  for (auto v : mesh.all_vertices()) {
    const auto r = positions.row(v.idx());
    mesh.set_point(v, Vec3(r[0], r[1], r[2]));
  }
}

} // namespace remora
