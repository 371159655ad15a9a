#include "remora/linalg/nested_dissection.h"

#include <string>

#include "remora/common/error.h"

#ifdef REMORA_WITH_GPL_SOLVERS
#include <cholmod.h>

#include "remora/linalg/cholmod_settings.h"
#endif

namespace remora {

std::vector<int> nested_dissection_keys(const Eigen::SparseMatrix<double>& a) {
  if (a.rows() != a.cols())
    throw InvalidArgument("nested_dissection_keys: the matrix is " + std::to_string(a.rows()) +
                          " x " + std::to_string(a.cols()) + "; give a square one");
#ifdef REMORA_WITH_GPL_SOLVERS
  const auto n = static_cast<std::size_t>(a.rows());
  if (n == 0) return {};
  Eigen::SparseMatrix<double> lower = a.triangularView<Eigen::Lower>();
  lower.makeCompressed();
  cholmod_sparse view = lower_view(n, static_cast<std::size_t>(lower.nonZeros()),
                                   lower.outerIndexPtr(), lower.innerIndexPtr(), nullptr);
  std::vector<int> perm(n), keys(n);
  cholmod_common c;
  cholmod_start(&c);
  c.print = 0;
  const int ok = cholmod_metis(&view, nullptr, 0, 1, perm.data(), &c);
  const int status = c.status;
  cholmod_finish(&c);
  if (status == CHOLMOD_NOT_INSTALLED) return {}; // a CHOLMOD built without METIS
  if (!ok) throw NumericalError("nested dissection: METIS failed (out of memory?)");
  for (std::size_t k = 0; k < n; ++k) keys[static_cast<std::size_t>(perm[k])] = static_cast<int>(k);
  return keys;
#else
  return {};
#endif
}

Eigen::SparseMatrix<double> ring_pattern(const Eigen::SparseMatrix<double>& minus_w, int k) {
  if (minus_w.rows() != minus_w.cols() || k < 1)
    throw InvalidArgument("ring_pattern: give a square matrix and k >= 1");
  Eigen::SparseMatrix<double> one = minus_w;
  for (Eigen::Index e = 0; e < one.nonZeros(); ++e) one.valuePtr()[e] = 1.0;
  Eigen::SparseMatrix<double> p = one;
  for (int i = 1; i < k; ++i) p = (p * one).eval();
  return p;
}

} // namespace remora
