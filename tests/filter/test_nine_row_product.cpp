// The structured nine-row products of the filter give the bits of Eigen's own
// products for every shape the filter uses (left 9 x K, right K x n, as
// matrices, blocks and transposes), on random factors with structural zeros
// and signed zeros.
#include <gtest/gtest.h>

#include <Eigen/Core>

#include <cstring>
#include <iostream>
#include <random>

#include "nine_row_product.hpp"

namespace {

using Eigen::MatrixXd;
using Matrix9d = Eigen::Matrix<double, 9, 9>;
using navimpact::filter::detail::nineRowProduct;

/// Random matrix: about a third exact zeros (some -0), whole zero rows/columns now and then.
MatrixXd sparseRandom(Eigen::Index r, Eigen::Index c, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, 5);
  MatrixXd M(r, c);
  for (Eigen::Index j = 0; j < c; ++j)
    for (Eigen::Index i = 0; i < r; ++i) {
      const int p = pick(rng);
      const double scale = std::pow(10.0, 6.0 * u(rng));
      M(i, j) = p == 0 ? 0.0 : p == 1 ? -0.0 : u(rng) * scale;
    }
  if (r > 0 && pick(rng) == 0) M.row(std::uniform_int_distribution<Eigen::Index>(0, r - 1)(rng)).setZero();
  if (c > 0 && pick(rng) == 0) M.col(std::uniform_int_distribution<Eigen::Index>(0, c - 1)(rng)).setZero();
  return M;
}

bool sameBits(const MatrixXd& a, const MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * std::size_t(a.size())) == 0;
}

/// nineRowProduct(out, l, r, assign) on a copy of @p start gives the bits of
/// Eigen's out = l r (@p assign) or out += l r on another copy.
template <class Out, class L, class R>
void expectSameBits(const Out& start, const L& l, const R& r, bool assign, const char* what) {
  Out e = start, o = start;
  if (assign)
    e.noalias() = l * r;
  else
    e.noalias() += l * r;
  nineRowProduct(o, l, r, assign);
  EXPECT_TRUE(sameBits(e, o)) << what;
}

}  // namespace

TEST(NineRowProduct, SameBitsAsEigenForEveryFilterShape) {
  const std::uint64_t seed = std::random_device{}();
  std::cout << "seed " << seed << "\n";
  std::mt19937_64 rng(seed);
  for (int rep = 0; rep < 20; ++rep)
    for (int m = 0; m <= 40; ++m) {
      SCOPED_TRACE("m = " + std::to_string(m) + ", repetition " + std::to_string(rep) + ", seed " +
                   std::to_string(seed));
      const Matrix9d A = sparseRandom(9, 9, rng), A2 = sparseRandom(9, 9, rng);
      const MatrixXd Lni = sparseRandom(9, m, rng), Lni2 = sparseRandom(9, m, rng);
      const MatrixXd P = sparseRandom(9 + m, 9 + m, rng);
      const Matrix9d D9 = sparseRandom(9, 9, rng);
      const MatrixXd Dni = sparseRandom(9, m, rng);

      // Matrix9d * (9 x m), assigned over random contents (F_nn F_ni, A P_ni)
      const MatrixXd R = sparseRandom(9, m, rng);
      expectSameBits(R, A, P.topRightCorner(9, m), true, "A * Pni");
      expectSameBits(R, A, Lni, true, "Fnn * Fni");
      // (9 x m) * (m x m) block, accumulated (B P_ii)
      expectSameBits(Dni, Lni, P.bottomRightCorner(m, m), false, "B * Pii");
      // (9 x m) * (9 x m)' into 9 x 9, accumulated (B P_ni', M B', F_ni Q_ii F_ni')
      expectSameBits(D9, Lni, P.topRightCorner(9, m).transpose(), false, "B * Pni'");
      expectSameBits(D9, Lni, Lni2.transpose(), false, "M * B'");
      // Matrix9d * Matrix9d (and transposed), assigned and accumulated
      expectSameBits(D9, A, A2, true, "A * Pnn");
      expectSameBits(D9, A, A2.transpose(), true, "M * A'");
      expectSameBits(D9, A, A2.transpose(), false, "+= M * A'");
    }
}
