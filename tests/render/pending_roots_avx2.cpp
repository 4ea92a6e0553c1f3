// The AVX2 half of pending_roots_test.cpp: compiled like the AVX2 kernel (CMakeLists.txt: -mavx2,
// no FMA contraction, the isa_avx2 namespace), it only runs neubauer_refine4 and world_normal4 on what the test
// hands over, so no template of the test's own is instantiated with AVX2 code.
#include "render/pending_roots.h"

namespace octiso {
OCTISO_ISA_BEGIN   // isa_avx2: AVX code only under that name (scripts/check_isa.py)
namespace test {

/// neubauer_refine4 on four brackets: in[j][lane] for j = c0, c1, c2, c3, a, fa, b, fb.
void refine4_for_test(int iterations, const double in[8][4], double out[4]) {
    V4d v[8];
    for (int j = 0; j < 8; ++j) load4(v[j], in[j]);
    store4(out, neubauer_refine4(iterations, v, v[4], v[5], v[6], v[7]));
}

/// world_normal4 on four hits: in[j][lane] for j = p (3), corners (8), spacing (3), direction (3);
/// ok[lane] nonzero where out holds the normal.
void normal4_for_test(const double in[17][4], double out[3][4], long long ok[4]) {
    V4d v[17], n[3];
    for (int j = 0; j < 17; ++j) load4(v[j], in[j]);
    const V4l done = world_normal4(v + 3, v, v + 11, v + 14, n);
    for (int a = 0; a < 3; ++a) store4(out[a], n[a]);
    for (int i = 0; i < 4; ++i) ok[i] = done[i];
}

}  // namespace test
OCTISO_ISA_END
}  // namespace octiso
