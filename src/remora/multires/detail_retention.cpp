#include "remora/multires/detail_retention.h"

#include <cmath>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/linalg/kharmonic.h"

namespace remora {

namespace {

/// Σ over `vertices` of the squared row norms of X − low_pass(X).
double detail_energy(const Eigen::MatrixXd& x, const std::vector<int>& vertices,
                     const LowPassFunction& low_pass, const char* what) {
  const Eigen::MatrixXd smooth = low_pass(x);
  if (smooth.rows() != x.rows() || smooth.cols() != x.cols())
    throw InvalidArgument(fmt::format("detail_retention: the low-pass of the {} is {} × {}, not "
                                      "{} × {}",
                                      what, smooth.rows(), smooth.cols(), x.rows(), x.cols()));
  double sum = 0.0;
  for (const int v : vertices) sum += (x.row(v) - smooth.row(v)).squaredNorm();
  return sum;
}

} // namespace

double detail_retention(const Eigen::MatrixXd& input, const Eigen::MatrixXd& result,
                        const std::vector<int>& vertices, const LowPassFunction& low_pass) {
  if (input.rows() != result.rows() || input.cols() != result.cols())
    throw InvalidArgument(fmt::format("detail_retention: the input is {} × {}, the result {} × {}",
                                      input.rows(), input.cols(), result.rows(), result.cols()));
  for (const int v : vertices)
    if (v < 0 || v >= input.rows())
      throw InvalidArgument(
          fmt::format("detail_retention: vertex {} is out of range ({} rows)", v, input.rows()));
  const double before = detail_energy(input, vertices, low_pass, "input");
  if (!(before > 0.0)) return 1.0;
  return std::sqrt(detail_energy(result, vertices, low_pass, "result") / before);
}

double detail_retention(Editor& editor, const std::vector<int>& vertices) {
  return detail_retention(positions_matrix(editor.input()), editor.positions(), vertices,
                          [&editor](const Eigen::MatrixXd& x) { return editor.low_pass(x); });
}

} // namespace remora
