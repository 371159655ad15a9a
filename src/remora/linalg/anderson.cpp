#include "remora/linalg/anderson.h"

#include <algorithm>
#include <cstddef>
#include <string>

#include <Eigen/Dense>

#include "remora/common/error.h"
#include "remora/common/parallel.h"

namespace remora {

AndersonAcceleration::AndersonAcceleration(int depth, int threads)
    : depth_(depth), threads_(threads) {
  if (depth < 1)
    throw InvalidArgument("Anderson acceleration: a history of " + std::to_string(depth) +
                          " differences; give 1 or more");
}

void AndersonAcceleration::clear() {
  count_ = 0;
  last_g_.resize(0);
  last_f_.resize(0);
}

void AndersonAcceleration::restart() {
  count_ = 0;
}

int AndersonAcceleration::history() const {
  return std::min(count_, depth_);
}

Eigen::VectorXd AndersonAcceleration::extrapolate(const Eigen::VectorXd& g,
                                                  const Eigen::VectorXd& f) {
  const Eigen::Index length = g.size();
  if (f.size() != length)
    throw InvalidArgument("Anderson acceleration: g and f have different lengths");
  int slot = -1; // the history's column the newest differences go to
  if (last_g_.size() == length) {
    if (dg_.cols() != depth_ || dg_.rows() != length) {
      dg_.resize(length, depth_);
      df_.resize(length, depth_);
      gram_.resize(depth_, depth_);
      count_ = 0;
    }
    slot = count_ % depth_;
    ++count_;
  } else {
    count_ = 0;
    last_g_.resize(length);
    last_f_.resize(length);
  }
  const int m = history();
  constexpr Eigen::Index kBlock = 8192;
  const auto blocks = static_cast<std::size_t>((length + kBlock - 1) / kBlock);
  // Per block: rows 0 … m − 1 the history's products with the new column, rows depth_ … with f.
  Eigen::MatrixXd partial(2 * depth_, static_cast<Eigen::Index>(blocks));
  parallel_blocks(blocks, threads_, [&](std::size_t b) {
    const Eigen::Index lo = static_cast<Eigen::Index>(b) * kBlock,
                       len = std::min(kBlock, length - lo);
    if (slot >= 0) {
      dg_.col(slot).segment(lo, len) = g.segment(lo, len) - last_g_.segment(lo, len);
      df_.col(slot).segment(lo, len) = f.segment(lo, len) - last_f_.segment(lo, len);
    }
    for (int j = 0; j < m; ++j) {
      const auto dj = df_.col(j).segment(lo, len);
      if (slot >= 0)
        partial(j, static_cast<Eigen::Index>(b)) = dj.dot(df_.col(slot).segment(lo, len));
      partial(depth_ + j, static_cast<Eigen::Index>(b)) = dj.dot(f.segment(lo, len));
    }
    last_g_.segment(lo, len) = g.segment(lo, len);
    last_f_.segment(lo, len) = f.segment(lo, len);
  });
  if (m == 0) return g;
  Eigen::VectorXd dot_f(m);
  for (int j = 0; j < m; ++j) {
    if (slot >= 0) gram_(j, slot) = gram_(slot, j) = partial.row(j).sum();
    dot_f[j] = partial.row(depth_ + j).sum();
  }
  Eigen::MatrixXd normal = gram_.topLeftCorner(m, m);
  normal.diagonal().array() += 1e-12 * normal.diagonal().maxCoeff() + 1e-300;
  const Eigen::VectorXd theta = normal.ldlt().solve(dot_f);
  Eigen::VectorXd out(length);
  parallel_blocks(blocks, threads_, [&](std::size_t b) {
    const Eigen::Index lo = static_cast<Eigen::Index>(b) * kBlock,
                       len = std::min(kBlock, length - lo);
    out.segment(lo, len) = g.segment(lo, len) - dg_.leftCols(m).middleRows(lo, len) * theta;
  });
  return out;
}

} // namespace remora
