// The machine's ceiling with 256-bit FMA work (issue 12), compiled with -mavx2 -mfma in this file
// alone (bench/CMakeLists.txt) and called only where the CPU has them. The renderer's kernel is
// the AVX2 one; on many Xeons all-core clocks drop under heavy 256-bit work, which the scalar
// ceiling loop does not see. Comparing the two ceilings at 16 threads tells whether the
// renderer's many-core loss could be clocks rather than memory.
#include <immintrin.h>

namespace octiso::bench {

/// 8 independent chains of 4-wide double FMAs, `iterations` rounds; returns their sum so the
/// work is observable.
double avx2_fma_chains(int iterations) {
    __m256d x[8];
    for (int k = 0; k < 8; ++k) x[k] = _mm256_set1_pd(1.0 + k);
    const __m256d a = _mm256_set1_pd(0.999999), b = _mm256_set1_pd(1e-7);
    for (int i = 0; i < iterations; ++i)
        for (__m256d& v : x) v = _mm256_fmadd_pd(v, a, b);
    __m256d s = x[0];
    for (int k = 1; k < 8; ++k) s = _mm256_add_pd(s, x[k]);
    alignas(32) double out[4];
    _mm256_store_pd(out, s);
    return out[0] + out[1] + out[2] + out[3];
}

}  // namespace octiso::bench
