// Sparse synthetic volumes built DIRECTLY as an octree, with no dense array: a few spherical
// bumps far apart in a huge domain (16384^3 and beyond), uniform background elsewhere. The field
// is analytic and evaluated only near the bumps; everything else becomes scalar leaves at the
// depth where it is uniform. The result is the same OctreeData<T> build_octree() would make from
// the dense array (same DFS post-order, exact forward-layer min/max, empty ranges for padding);
// tests check that node for node on small grids. `--synthetic sparse-spheres:N` uses it.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "octiso/build.h"
#include "octiso/volume.h"

namespace octiso {

/// One bump: value peak * (1 - |p - centre|^2 / radius^2) where that is positive, background
/// elsewhere (index space, voxel p at integer coordinates).
struct SparseBlob {
    std::array<double, 3> centre{};
    double radius = 1;
    double peak = 100;
};

struct SparseSpheres {
    Dims dims;
    std::vector<SparseBlob> blobs;   ///< their supports must not overlap (max == sum there)
    double background = 0;

    /// Value of voxel (x, y, z) as stored in T (integer T: rounded).
    template <typename T> T value(uint32_t x, uint32_t y, uint32_t z) const;
    /// The closed voxel box [lo, hi] outside which blob i contributes nothing (clipped to the data;
    /// may be empty: lo > hi on some axis).
    std::array<std::array<int64_t, 3>, 2> support(size_t i) const;
};

/// The standard layout for `--synthetic sparse-spheres:N` (N >= 64): five blobs of radius ~5-12,
/// one near the origin, one near the far corner (cell indices ~N-6), one cut by the far faces of
/// the data, two in between, all on an N^3 grid.
SparseSpheres sparse_spheres_layout(uint32_t n);

/// Parses "sparse-spheres:N" (N in [64, 2^30]); returns 0 if `text` is not a sparse-spheres spec.
/// Throws Error(flag, ...) for a sparse-spheres spec with a bad N.
uint32_t parse_sparse_spheres(std::string_view text, const std::string& flag = "--synthetic");

/// The octree of `field`, built top-down without a dense array. Serial; cost grows with the
/// blobs' volume and log2(N), not with N^3. Throws Error if the field is not finite in T.
template <typename T> OctreeData<T> build_sparse_octree(const SparseSpheres& field);

}  // namespace octiso
