// per_face(): a value per face computed in parallel, in face order (internal: not installed).
#pragma once

#include <vector>

#include "remora/common/parallel.h"
#include "remora/mesh/mesh.h"

namespace remora {

/// value(f) for every face f, by idx() (T{} for a deleted face), computed on all hardware threads.
/// `value` must only read the mesh; the result does not depend on the number of threads, so
/// sums taken over it in face order are the same bits as a sequential loop's.
template <class T, class Value>
std::vector<T> per_face(const Mesh& mesh, Value&& value) {
  std::vector<T> out(mesh.n_faces());
  parallel_for(out.size(), 0, [&](std::size_t i) {
    const FaceHandle f(static_cast<int>(i));
    if (!mesh.status(f).deleted()) out[i] = value(f);
  });
  return out;
}

} // namespace remora
