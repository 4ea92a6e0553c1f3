// AnyOctree: an octree of any of the 8 scalar types behind one non-template handle, for callers
// that learn the type at run time (the tools, Python, an MPI driver). It is built from a volume
// or opened from a step of a .oct file, and answers what the typed API answers: info, save,
// render, decode. The one switch over ScalarType lives in any_octree.cpp; the typed path
// (build.h, oct_file.h, render.h) stays the place for code that knows its T.
//
// Ownership: copies share one immutable octree (shared ownership of the built arrays or of the
// mapped file), so a step handed out stays valid however long the caller keeps it. Every const
// method may be called from several threads at once.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>
#include <optional>
#include <span>
#include <string>

#include "octiso/build.h"
#include "octiso/camera.h"
#include "octiso/debug_trace.h"
#include "octiso/frame.h"
#include "octiso/oct_file.h"
#include "octiso/octree.h"
#include "octiso/render.h"
#include "octiso/volume.h"

namespace octiso {

class LoadedVolume;

/// What an octree is, for reports: the header fields of its file and the sizes of its arrays.
struct AnyOctreeInfo {
    ScalarType type = ScalarType::u8;
    Dims dims;
    Placement placement;
    int dmax = 0;
    StepSizes sizes;                                   ///< nodes and scalar leaves per depth, bytes
    std::optional<std::array<double, 2>> iso_range;    ///< built or converted with --iso-range
    double tolerance = 0.0;                            ///< 0: lossless
    /// [min, max] over the stored values of every data cell, read from the root's 8 child ranges
    /// (so widened by the tolerance of a lossy tree); empty when the grid has no cell (an extent 1).
    std::optional<std::array<double, 2>> value_range;
    /// Stored-to-real values: value_range, iso_range and tolerance are stored values; tools map
    /// them with value_scale.real_range() before reporting (CONVENTIONS 2b).
    ValueScale value_scale;
    uint8_t flipped_axes = 0;                          ///< source axes reversed at conversion
    uint64_t dense_bytes = 0;                          ///< dims x scalar size: what decode() writes
    std::optional<BuildPhases> build_phases;           ///< a tree built in memory: its build's phases (build.h)
    std::string source;                                ///< the file or input it came from
};

class AnyOctree {
public:
    /// Builds the octree of `volume` (its type, dims and placement). Throws what build_octree()
    /// throws; options.source_name defaults to volume.source().
    static AnyOctree build(const LoadedVolume& volume, const BuildOptions& options);
    /// Builds from a typed view placed by `placement` (instantiated for the 8 types in the .cpp).
    template <typename T>
    static AnyOctree build(const VolumeView<T>& volume, const Placement& placement, const BuildOptions& options);
    /// Takes over an octree already built (e.g. build_sparse_octree()); `options` records the
    /// iso-range, tolerance and source name it was built with.
    template <typename T>
    static AnyOctree adopt(OctreeData<T>&& data, const Placement& placement, const BuildOptions& options = {});

    /// Step k of `file`, validated as OctFile::step() does (thread-safe, once per step). The
    /// handle shares ownership of the file, so the mapping lives as long as any step of it.
    /// Throws Error(file path, ...) if k is out of range or the step is bad.
    static AnyOctree step(std::shared_ptr<const OctFile> file, uint32_t k);
    /// OctFile::open(path, verify), then step k of it.
    static AnyOctree open(const std::string& path, uint32_t k = 0, Verify verify = Verify::Full);

    ScalarType type() const;
    Dims dims() const;
    const Placement& placement() const;
    int dmax() const;
    /// The header and sizes; value_range reads the root node only, so this is cheap (but the sizes
    /// of a step opened with Verify::Touched count every node: OctFile::step_sizes).
    AnyOctreeInfo info() const;
    /// The data's exact stored range from the root node (info().value_range without the sizes).
    std::optional<std::array<double, 2>> value_range() const;
    /// The file this step was opened from; null for a built octree.
    const std::shared_ptr<const OctFile>& file() const;

    /// The header a .oct file of this octree carries (step_count 0: OctWriter::finish() counts).
    OctInfo oct_info() const;
    /// Appends this octree as the next step of `writer`, whose OctInfo must match oct_info() in
    /// type and dims (the writer checks). Not thread-safe for one writer.
    void append_to(OctWriter& writer) const;
    /// Writes a one-step .oct file (temporary + rename, as OctWriter does). Throws Error on I/O.
    void save(const std::string& path) const;

    /// What the renderer must refuse: the iso-range recorded at build or in the file, naming the
    /// file (or the build's source name).
    RenderLimits render_limits() const;
    /// A persistent Renderer over this octree with render_limits(). It shares ownership of the
    /// octree's storage (Renderer::keep_alive), so it may outlive this handle.
    Renderer make_renderer(const RenderOptions& options) const;
    /// One frame in one call (make_renderer(options).render(camera)). Throws Error on bad options
    /// or camera.
    Frame render(const Camera& camera, const RenderOptions& options) const;

    /// The path of the primary ray of pixel (x, y) through this octree (octiso-render --debug-pixel);
    /// debug_trace.h. Throws Error("--debug-pixel", ...) for a pixel outside the image.
    PixelTrace trace_pixel(const Camera& camera, const RenderOptions& options, int x, int y) const;

    /// The dense x-fastest array back (decode_to_dense), dense_bytes() bytes in the byte order
    /// `order`. Throws Error unless out.size() == dense_bytes(); `out` needs no alignment.
    void decode(std::span<std::byte> out, std::endian order = std::endian::native) const;
    uint64_t dense_bytes() const;
    /// Layers z0 .. z1-1 of it (z0 <= z1 <= dims().z): x*y*(z1-z0) values, layer z0 first
    /// (decode.h decode_layers), so a step larger than memory can be written out slab by slab.
    void decode_layers(uint32_t z0, uint32_t z1, std::span<std::byte> out, std::endian order = std::endian::native) const;
    /// The voxels of the plane x = `x` (< dims().x) as doubles (exact for every scalar type),
    /// element y + ny * z: the ghost face a sort-last neighbour needs (RenderOptions::ghost_plane).
    std::vector<double> x_plane(uint32_t x) const;

    /// The typed view, or null when T is not type(): the way back to the typed API.
    template <typename T> const Octree<T>* as() const;

    struct Impl;

private:
    explicit AnyOctree(std::shared_ptr<const Impl> impl);
    std::shared_ptr<const Impl> impl_;
};

}  // namespace octiso
