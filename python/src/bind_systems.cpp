// The mathematics behind the editor for people who want it: the cotan Laplacian W and the mixed
// areas of Eq. 1 (geometry/laplacian.h, geometry/measures.h) and the k-harmonic system of §3 and §5
// (linalg/kharmonic.h). Sparse matrices leave as their compressed-column arrays; the Python
// package makes scipy.sparse.csc_matrix objects of them.
#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "bindings.h"
#include "convert.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"
#include "remora/linalg/kharmonic.h"

namespace remora::python {

namespace {

template <class T, class Source>
py::array_t<T> copy_array(const Source* data, std::size_t n) {
  py::array_t<T> out(static_cast<py::ssize_t>(n));
  T* p = out.mutable_data();
  for (std::size_t i = 0; i < n; ++i) p[i] = static_cast<T>(data[i]);
  return out;
}

/// (data, indices, indptr, (rows, cols)) of a compressed-column matrix.
py::tuple csc_arrays(SparseMatrix a) {
  a.makeCompressed();
  const auto nnz = static_cast<std::size_t>(a.nonZeros());
  return py::make_tuple(
      copy_array<double>(a.valuePtr(), nnz), copy_array<std::int32_t>(a.innerIndexPtr(), nnz),
      copy_array<std::int32_t>(a.outerIndexPtr(), static_cast<std::size_t>(a.outerSize()) + 1),
      py::make_tuple(a.rows(), a.cols()));
}

py::tuple laplacian(const py::handle& vertices, const py::handle& faces) {
  const Mesh mesh = mesh_arg(vertices, faces);
  SparseMatrix w;
  {
    py::gil_scoped_release release;
    w = cotan_weights(mesh);
  }
  return csc_arrays(std::move(w));
}

py::array_t<double> mixed_areas(const py::handle& vertices, const py::handle& faces) {
  const Mesh mesh = mesh_arg(vertices, faces);
  const Eigen::VectorXd a = vertex_areas_mixed(mesh);
  return copy_array<double>(a.data(), static_cast<std::size_t>(a.size()));
}

/// The labels of Region: the support's vertices free, handle j's vertices j, the rest fixed.
Region region_arg(std::size_t n, const py::handle& support, const py::sequence& handles) {
  Region region = Region::all_fixed(n);
  for (const int v : indices_arg(support, "support", n, false))
    region.label[static_cast<std::size_t>(v)] = Region::kFree;
  for (std::size_t j = 0; j < handles.size(); ++j) {
    const std::string name = fmt::format("handles[{}]", j);
    for (const int v : indices_arg(handles[j], name.c_str(), n, false)) {
      int& label = region.label[static_cast<std::size_t>(v)];
      if (label >= 0)
        throw InvalidArgument(fmt::format("{}: vertex {} is also in handle {}", name, v, label));
      if (label != Region::kFree)
        throw InvalidArgument(fmt::format("{}: vertex {} is not in the support", name, v));
      label = static_cast<int>(j);
    }
  }
  return region;
}

py::tuple kharmonic(const py::handle& vertices, const py::handle& faces, const py::handle& support,
                    const py::sequence& handles, int k, const std::string& areas) {
  const Mesh mesh = mesh_arg(vertices, faces);
  const Region region = region_arg(mesh.n_vertices(), support, handles);
  KHarmonicOptions options;
  options.k = k;
  options.areas = parse_area_weights(areas);
  KHarmonicSystem system;
  {
    py::gil_scoped_release release;
    system = assemble_kharmonic(mesh, region, options);
  }
  return py::make_tuple(
      csc_arrays(std::move(system.matrix)), csc_arrays(std::move(system.coupling)),
      copy_array<std::int64_t>(system.free_vertices.data(), system.free_vertices.size()),
      copy_array<std::int64_t>(system.constrained_vertices.data(),
                               system.constrained_vertices.size()),
      system.symmetric);
}

} // namespace

void bind_systems(py::module_& m) {
  m.def("cotan_laplacian", &laplacian, py::arg("V"), py::arg("F"));
  m.def("mixed_areas", &mixed_areas, py::arg("V"), py::arg("F"));
  m.def("kharmonic_system", &kharmonic, py::arg("V"), py::arg("F"), py::arg("support"),
        py::arg("handles"), py::arg("k"), py::arg("areas"));
}

} // namespace remora::python
