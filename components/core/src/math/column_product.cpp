#include "navbus/core/math/column_product.hpp"

#include <array>

// The kernel is x86-64 code (AVX2 and FMA, chosen at run time); elsewhere Eigen's product.
#if defined(__x86_64__)
#define NAVBUS_X86_KERNELS 1
#include <immintrin.h>
#else
#define NAVBUS_X86_KERNELS 0
#endif

namespace navbus::core {

#if NAVBUS_X86_KERNELS
namespace {

// A kernel of NB blocks of four rows and NC columns at a time: NB x NC accumulators (at most
// twelve of the sixteen registers, enough independent chains to hide the multiply-add's
// latency), per k one broadcast of each column's b(k, j) and NB x NC fused multiply-adds. a's
// columns are padded to 4 NB rows with zeros; the last block is stored through a mask.
template <int NB, int NC>
__attribute__((target("avx2,fma"))) inline void fmaColumns(int n, const double* a_padded,
                                                           const double* b, int ldb, double* c,
                                                           int ldc, __m256i last_mask) {
  constexpr int kRows = 4 * NB;
  __m256d acc[NB * NC];
#pragma GCC unroll 16
  for (int i = 0; i < NB * NC; ++i) acc[i] = _mm256_setzero_pd();
  for (int k = 0; k < n; ++k) {
    const double* ak = a_padded + static_cast<std::ptrdiff_t>(k) * kRows;
#pragma GCC unroll 16
    for (int col = 0; col < NC; ++col) {
      const __m256d bk = _mm256_broadcast_sd(b + static_cast<std::ptrdiff_t>(col) * ldb + k);
#pragma GCC unroll 16
      for (int i = 0; i < NB; ++i)
        acc[col * NB + i] = _mm256_fmadd_pd(_mm256_load_pd(ak + 4 * i), bk, acc[col * NB + i]);
    }
  }
#pragma GCC unroll 16
  for (int col = 0; col < NC; ++col) {
    double* cj = c + static_cast<std::ptrdiff_t>(col) * ldc;
#pragma GCC unroll 16
    for (int i = 0; i < NB - 1; ++i) _mm256_storeu_pd(cj + 4 * i, acc[col * NB + i]);
    _mm256_maskstore_pd(cj + 4 * (NB - 1), last_mask, acc[col * NB + NB - 1]);
  }
}

template <int NB>
__attribute__((target("avx2,fma"))) void fmaKernel(int n, int cols, const double* a_padded,
                                                   const double* b, int ldb, double* c, int ldc,
                                                   __m256i last_mask) {
  constexpr int kColumns = NB >= 12 ? 1 : 12 / NB;
  int j = 0;
  for (; j + kColumns <= cols; j += kColumns) {
    fmaColumns<NB, kColumns>(n, a_padded, b + static_cast<std::ptrdiff_t>(j) * ldb, ldb,
                             c + static_cast<std::ptrdiff_t>(j) * ldc, ldc, last_mask);
  }
  for (; j < cols; ++j) {
    fmaColumns<NB, 1>(n, a_padded, b + static_cast<std::ptrdiff_t>(j) * ldb, ldb,
                      c + static_cast<std::ptrdiff_t>(j) * ldc, ldc, last_mask);
  }
}

constexpr int kMaxBlocks = kMaxColumnProductSize / 4;

/// The kernel of `blocks` blocks (NB..kMaxBlocks).
template <int NB>
__attribute__((target("avx2,fma"))) void fmaBlocks(int blocks, int n, int cols,
                                                   const double* a_padded, const double* b, int ldb,
                                                   double* c, int ldc, __m256i last_mask) {
  if constexpr (NB < kMaxBlocks) {
    if (blocks > NB) {
      fmaBlocks<NB + 1>(blocks, n, cols, a_padded, b, ldb, c, ldc, last_mask);
      return;
    }
  }
  fmaKernel<NB>(n, cols, a_padded, b, ldb, c, ldc, last_mask);
}

__attribute__((target("avx2,fma"))) void fmaProduct(int n, int cols, const double* a, int lda,
                                                    const double* b, int ldb, double* c, int ldc) {
  const int blocks = (n + 3) / 4;
  const int rows = 4 * blocks;
  alignas(32) std::array<double, kMaxColumnProductSize * kMaxColumnProductSize> padded;
  for (int k = 0; k < n; ++k) {
    for (int r = 0; r < rows; ++r)
      padded[static_cast<std::size_t>(k * rows + r)] = r < n ? a[k * lda + r] : 0.0;
  }
  const int last = n - 4 * (blocks - 1);  // rows of the last block, 1..4
  const __m256i mask =
      _mm256_setr_epi64x(-1, last > 1 ? -1 : 0, last > 2 ? -1 : 0, last > 3 ? -1 : 0);
  fmaBlocks<1>(blocks, n, cols, padded.data(), b, ldb, c, ldc, mask);
}

bool cpuHasAvx2Fma() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") != 0 && __builtin_cpu_supports("fma") != 0;
}

}  // namespace
#endif

bool columnProductUsesFma() {
#if NAVBUS_X86_KERNELS
  static const bool has = cpuHasAvx2Fma();
  return has;
#else
  return false;
#endif
}

void columnProduct(int n, int cols, const double* a, int lda, const double* b, int ldb, double* c,
                   int ldc) {
  if (n <= 0 || cols <= 0) return;
#if NAVBUS_X86_KERNELS
  if (columnProductUsesFma() && n <= kMaxColumnProductSize) {
    fmaProduct(n, cols, a, lda, b, ldb, c, ldc);
    return;
  }
#endif
  using Stride = Eigen::OuterStride<>;
  const Eigen::Map<const Eigen::MatrixXd, 0, Stride> am(a, n, n, Stride(lda));
  const Eigen::Map<const Eigen::MatrixXd, 0, Stride> bm(b, n, cols, Stride(ldb));
  Eigen::Map<Eigen::MatrixXd, 0, Stride> cm(c, n, cols, Stride(ldc));
  cm.noalias() = am * bm;
}

}  // namespace navbus::core
