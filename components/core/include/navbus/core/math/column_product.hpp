// C = A B for a small square A (n x n, n <= kMaxColumnProductSize) and a wide B (n rows, many
// columns), the shape of the GLR's signature recursion (every onset's signatures propagated by
// one matrix). On a CPU with AVX2 and FMA (chosen at run time, as glibc chooses its libm
// variants) a kernel four rows wide with fused multiply-adds; elsewhere Eigen's product. The
// two differ in the last bits (fused rounding, summation order), as libm's variants do: a run
// is reproducible on one machine, not bit for bit across machines with and without FMA.
#pragma once

#include <Eigen/Core>

namespace navbus::core {

inline constexpr int kMaxColumnProductSize = 40;

/// Whether columnProduct uses the AVX2 + FMA kernel on this CPU.
bool columnProductUsesFma();

/// c(0:n, j) = a(0:n, 0:n) b(0:n, j) for j < cols, a and b column-major with leading
/// dimensions lda and ldb (c: ldc); only c's first n rows of each column are written.
void columnProduct(int n, int cols, const double* a, int lda, const double* b, int ldb, double* c,
                   int ldc);

}  // namespace navbus::core
