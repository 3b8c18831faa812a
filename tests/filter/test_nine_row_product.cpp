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

      // Matrix9d * (9 x m), assigned (F_nn F_ni, A P_ni)
      {
        MatrixXd e(9, m), o = sparseRandom(9, m, rng);
        e.noalias() = A * P.topRightCorner(9, m);
        nineRowProduct(o, A, P.topRightCorner(9, m), true);
        EXPECT_TRUE(sameBits(e, o)) << "A * Pni";
        e.noalias() = A * Lni;
        nineRowProduct(o, A, Lni, true);
        EXPECT_TRUE(sameBits(e, o)) << "Fnn * Fni";
      }
      // (9 x m) * (m x m) block, accumulated (B P_ii)
      {
        MatrixXd e = Dni, o = Dni;
        e.noalias() += Lni * P.bottomRightCorner(m, m);
        nineRowProduct(o, Lni, P.bottomRightCorner(m, m), false);
        EXPECT_TRUE(sameBits(e, o)) << "B * Pii";
      }
      // (9 x m) * (9 x m)' into 9 x 9, accumulated and assigned (B P_ni', M B', F_ni Q_ii F_ni')
      {
        Matrix9d e = D9, o = D9;
        e.noalias() += Lni * P.topRightCorner(9, m).transpose();
        nineRowProduct(o, Lni, P.topRightCorner(9, m).transpose(), false);
        EXPECT_TRUE(sameBits(e, o)) << "B * Pni'";
        e = D9;
        o = D9;
        e.noalias() += Lni * Lni2.transpose();
        nineRowProduct(o, Lni, Lni2.transpose(), false);
        EXPECT_TRUE(sameBits(e, o)) << "M * B'";
      }
      // Matrix9d * Matrix9d (and transposed), assigned and accumulated
      {
        Matrix9d e, o = D9;
        e.noalias() = A * A2;
        nineRowProduct(o, A, A2, true);
        EXPECT_TRUE(sameBits(e, o)) << "A * Pnn";
        e.noalias() = A * A2.transpose();
        nineRowProduct(o, A, A2.transpose(), true);
        EXPECT_TRUE(sameBits(e, o)) << "M * A'";
        e = D9;
        o = D9;
        e.noalias() += A * A2.transpose();
        nineRowProduct(o, A, A2.transpose(), false);
        EXPECT_TRUE(sameBits(e, o)) << "+= M * A'";
      }
    }
}
