// Products with nine rows on the left (the navigation rows of the error state),
// computed with Eigen's own summation order but skipping exact zeros.
//
// Eigen 3.4 evaluates a product of a 9-row left factor through its GEMM kernel
// (rows 0-7 in packets of 4, row 8 by the scalar path; depth in one block for
// our sizes): every coefficient is dst + (((0 + l_0 r_0) + l_1 r_1) + ...),
// the terms in increasing depth order. The functions below do the same
// additions in the same order, so they give the same bits, and they skip terms
// whose right factor is an exact zero and, per depth index, the left rows
// outside the nonzero range: adding a product that is exactly zero to a sum
// that started at +0 never changes it (the sum cannot become -0). Only
// non-finite inputs (0 * inf) could differ; the filter checks P after every
// propagation. The left factors of the filter are sparse (F_ni has three
// nonzero rows per column, B = Phi_ni none in the position rows of the
// gyroscope columns) and the right factors often are (Q_nn, the IMU blocks of
// Q); tests/filter/test_nine_row_product.cpp checks the bits against Eigen for
// every shape the filter uses. Where the CPU has AVX (checked once at run time)
// the two-column kernel runs on 4-wide packets: still a multiply, then an add
// per lane (no fused multiply-add), so the bits do not depend on the CPU.
#pragma once

#include <Eigen/Core>

#include <array>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace navimpact::filter::detail {

#if defined(__SSE2__)
/// Two columns of a 9-row product: a0[i] = sum_k L(i, k) r0[k] and a1 likewise,
/// each sum from +0 in increasing k, skipping k without a used column of L or
/// with both right factors zero. Rows 0-7 in packets, row 8 alone; per lane
/// the same multiply and add as Eigen's kernel (no fused multiply-add).
inline void twoColumnsSse2(const double* l, Eigen::Index ls, const double* rc0, const double* rc1,
                           Eigen::Index K, const bool* used, double* a0, double* a1) {
  __m128d p00 = _mm_setzero_pd(), p01 = p00, p02 = p00, p03 = p00;
  __m128d p10 = p00, p11 = p00, p12 = p00, p13 = p00;
  double s0 = 0.0, s1 = 0.0;
  for (Eigen::Index k = 0; k < K; ++k) {
    const double r0 = rc0[k], r1 = rc1[k];
    if ((r0 == 0.0 && r1 == 0.0) || !used[k]) continue;
    const double* c = l + k * ls;
    const __m128d b0 = _mm_set1_pd(r0), b1 = _mm_set1_pd(r1);
    const __m128d c0 = _mm_loadu_pd(c), c1 = _mm_loadu_pd(c + 2), c2 = _mm_loadu_pd(c + 4),
                  c3 = _mm_loadu_pd(c + 6);
    p00 = _mm_add_pd(p00, _mm_mul_pd(c0, b0));
    p01 = _mm_add_pd(p01, _mm_mul_pd(c1, b0));
    p02 = _mm_add_pd(p02, _mm_mul_pd(c2, b0));
    p03 = _mm_add_pd(p03, _mm_mul_pd(c3, b0));
    p10 = _mm_add_pd(p10, _mm_mul_pd(c0, b1));
    p11 = _mm_add_pd(p11, _mm_mul_pd(c1, b1));
    p12 = _mm_add_pd(p12, _mm_mul_pd(c2, b1));
    p13 = _mm_add_pd(p13, _mm_mul_pd(c3, b1));
    s0 += c[8] * r0;
    s1 += c[8] * r1;
  }
  _mm_storeu_pd(a0, p00);
  _mm_storeu_pd(a0 + 2, p01);
  _mm_storeu_pd(a0 + 4, p02);
  _mm_storeu_pd(a0 + 6, p03);
  _mm_storeu_pd(a1, p10);
  _mm_storeu_pd(a1 + 2, p11);
  _mm_storeu_pd(a1 + 4, p12);
  _mm_storeu_pd(a1 + 6, p13);
  a0[8] = s0;
  a1[8] = s1;
}

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#define NAVIMPACT_NINE_ROW_AVX 1
/// The same sums with 4-wide packets where the CPU has AVX (chosen at run
/// time): each lane still multiplies, then adds, in the same order (AVX
/// without FMA), so the bits are those of twoColumnsSse2.
__attribute__((target("avx"))) inline void twoColumnsAvx(const double* l, Eigen::Index ls, const double* rc0,
                                                          const double* rc1, Eigen::Index K, const bool* used,
                                                          double* a0, double* a1) {
  __m256d p00 = _mm256_setzero_pd(), p01 = p00, p10 = p00, p11 = p00;
  double s0 = 0.0, s1 = 0.0;
  for (Eigen::Index k = 0; k < K; ++k) {
    const double r0 = rc0[k], r1 = rc1[k];
    if ((r0 == 0.0 && r1 == 0.0) || !used[k]) continue;
    const double* c = l + k * ls;
    const __m256d b0 = _mm256_set1_pd(r0), b1 = _mm256_set1_pd(r1);
    const __m256d c0 = _mm256_loadu_pd(c), c1 = _mm256_loadu_pd(c + 4);
    p00 = _mm256_add_pd(p00, _mm256_mul_pd(c0, b0));
    p01 = _mm256_add_pd(p01, _mm256_mul_pd(c1, b0));
    p10 = _mm256_add_pd(p10, _mm256_mul_pd(c0, b1));
    p11 = _mm256_add_pd(p11, _mm256_mul_pd(c1, b1));
    s0 += c[8] * r0;
    s1 += c[8] * r1;
  }
  _mm256_storeu_pd(a0, p00);
  _mm256_storeu_pd(a0 + 4, p01);
  _mm256_storeu_pd(a1, p10);
  _mm256_storeu_pd(a1 + 4, p11);
  a0[8] = s0;
  a1[8] = s1;
}
inline bool hasAvx() { return __builtin_cpu_supports("avx"); }
#else
inline bool hasAvx() { return false; }
#endif
#endif  // __SSE2__

/// dst = L R (assign) or dst += L R, with L a plain column-major 9 x K matrix
/// and R K x n (any Eigen expression with coefficient access: blocks,
/// transposes). dst is 9 x n and must not alias L or R.
template <class Dst, class Lhs, class Rhs>
void nineRowProduct(Dst&& dst, const Lhs& L, const Rhs& R, bool assign) {
  const Eigen::Index K = L.cols(), n = R.cols();
  // Shapes Eigen does not send through its GEMM kernel (a lazy coefficient
  // product below 20 = rows + depth + columns, a matrix-vector product, no
  // depth) are left to Eigen.
  constexpr Eigen::Index kMaxDepth = 64;
  if (9 + K + n < 20 || n <= 1 || K == 0 || K > kMaxDepth || n > kMaxDepth) {
    if (assign)
      dst.noalias() = L * R;
    else
      dst.noalias() += L * R;
    return;
  }
  // L is a plain column-major matrix (9 rows, contiguous columns)
  const double* l = L.data();
  const Eigen::Index ls = L.outerStride();
  // depth indices whose column of L is not all zeros
  std::array<bool, kMaxDepth> used{};
  for (Eigen::Index k = 0; k < K; ++k) {
    const double* c = l + k * ls;
    bool any = false;
    for (int i = 0; i < 9; ++i) any = any || c[i] != 0.0;
    used[k] = any;
  }
  // two columns of dst at a time (each coefficient still sums its own terms in
  // depth order; a zero right factor adds an exact zero)
  auto store = [&](Eigen::Index j, const double* acc) {
    if (assign)
      for (int i = 0; i < 9; ++i) dst(i, j) = 0.0 + acc[i];
    else
      for (int i = 0; i < 9; ++i) dst(i, j) += acc[i];
  };
  // R in a contiguous column-major copy (it may be a transposed block)
  double rb[kMaxDepth * kMaxDepth];
  for (Eigen::Index jj = 0; jj < n; ++jj)
    for (Eigen::Index k = 0; k < K; ++k) rb[jj * K + k] = R(k, jj);
  Eigen::Index j = 0;
#if defined(__SSE2__)
  static const bool avx = hasAvx();
  for (; j + 1 < n; j += 2) {
    double a0[9], a1[9];
#if defined(NAVIMPACT_NINE_ROW_AVX)
    if (avx)
      twoColumnsAvx(l, ls, rb + j * K, rb + (j + 1) * K, K, used.data(), a0, a1);
    else
#endif
      twoColumnsSse2(l, ls, rb + j * K, rb + (j + 1) * K, K, used.data(), a0, a1);
    store(j, a0);
    store(j + 1, a1);
  }
#endif
  for (; j < n; ++j) {
    double a0[9] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    for (Eigen::Index k = 0; k < K; ++k) {
      const double r0 = rb[j * K + k];
      if (r0 == 0.0 || !used[k]) continue;
      const double* c = l + k * ls;
      for (int i = 0; i < 9; ++i) a0[i] += c[i] * r0;
    }
    store(j, a0);
  }
}

}  // namespace navimpact::filter::detail
