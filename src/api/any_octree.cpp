// AnyOctree (include/octiso/any_octree.h): a small virtual interface, Impl, with one TypedOctree<T>
// per scalar type behind it. The run-time type is turned into T exactly twice, both here: when a
// LoadedVolume is built and when a file step is opened. Everything else is a virtual call per
// operation (never per voxel or per ray), so the typed kernels run as they do from typed code.
#include "octiso/any_octree.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "octiso/debug_trace.h"
#include "octiso/decode.h"
#include "octiso/error.h"
#include "octiso/loaded_volume.h"

namespace octiso {

struct AnyOctree::Impl {
    virtual ~Impl() = default;
    virtual ScalarType type() const = 0;
    virtual Dims dims() const = 0;
    virtual int dmax() const = 0;
    virtual StepSizes sizes() const = 0;
    virtual std::optional<BuildPhases> build_phases() const = 0;
    virtual std::optional<std::array<double, 2>> value_range() const = 0;
    virtual void append_to(OctWriter& writer) const = 0;
    virtual Renderer make_renderer(const RenderOptions& options, const RenderLimits& limits) const = 0;
    virtual void decode(uint32_t z0, uint32_t z1, std::byte* out, bool swap_bytes) const = 0;   // layers [z0, z1)
    virtual PixelTrace trace_pixel(const Camera& camera, const RenderOptions& options, int x, int y) const = 0;
    virtual const void* typed_view() const = 0;   // the Octree<T> for as<T>()
    virtual std::vector<double> x_plane(uint32_t x) const = 0;

    Placement placement;
    std::optional<std::array<double, 2>> iso_range;
    double tolerance = 0.0;
    ValueScale value_scale;
    uint8_t flipped_axes = 0;
    std::string source;
    std::shared_ptr<const OctFile> file;   // keeps the mapping alive for a file step
};

namespace {

/// Where a TypedOctree's arrays live: built in memory (data) or in a mapped file (the base's file).
template <typename T> class TypedOctree final : public AnyOctree::Impl {
public:
    /// A built octree: the view points into `data`, which this object now owns.
    explicit TypedOctree(OctreeData<T>&& data) : data_(std::move(data)), tree_(data_->view()) {
        sizes_.interior_bytes = data_->stats.interior_bytes;
        sizes_.minmax_bytes = data_->stats.minmax_bytes;
        sizes_.cap_bytes = data_->stats.cap_bytes;
        sizes_.nodes_per_depth = data_->stats.nodes_per_depth;
        sizes_.scalar_leaves_per_depth = data_->stats.scalar_leaves_per_depth;
    }
    /// A file step: the view points into the mapping, which the base's `file` keeps alive; its
    /// sizes are asked of the file when wanted (under Verify::Touched that reads every node).
    TypedOctree(const Octree<T>& tree, uint32_t step) : tree_(tree), step_(step) {}

    ScalarType type() const override { return scalar_type_of<T>(); }
    Dims dims() const override { return tree_.dims(); }
    int dmax() const override { return tree_.dmax(); }
    std::optional<BuildPhases> build_phases() const override {
        return data_ ? std::optional<BuildPhases>(data_->stats.phases) : std::nullopt;
    }
    StepSizes sizes() const override { return data_ ? sizes_ : file->step_sizes(step_); }

    std::optional<std::array<double, 2>> value_range() const override {
        // The root is always stored (dmax >= 2), and its children's exact range together
        // covers every data cell (octree.h, ChildBounds: kept exact per node).
        const ChildBounds<T>& root = tree_.node(0, 0).bounds;
        const double lo = root.range_lo(), hi = root.range_hi();
        if (lo > hi) return std::nullopt;
        return std::array<double, 2>{lo, hi};
    }

    void append_to(OctWriter& writer) const override { writer.add_step(tree_); }

    Renderer make_renderer(const RenderOptions& options, const RenderLimits& limits) const override {
        return Renderer(tree_, placement, options, limits);
    }

    void decode(uint32_t z0, uint32_t z1, std::byte* out, bool swap_bytes) const override {
        const uint64_t n = uint64_t(tree_.dims().x) * tree_.dims().y * (z1 - z0);
        // In place when `out` can hold T directly; else through an aligned buffer.
        const bool aligned = reinterpret_cast<uintptr_t>(out) % alignof(T) == 0;
        std::vector<T> buffer(aligned ? 0 : size_t(n));
        T* values = aligned ? reinterpret_cast<T*>(out) : buffer.data();
        decode_layers(tree_, z0, z1, values);
        if (swap_bytes)
            for (uint64_t i = 0; i < n; ++i) values[i] = VolumeView<T>::byte_swapped(values[i]);
        if (!aligned) std::memcpy(out, buffer.data(), size_t(n) * sizeof(T));
    }

    PixelTrace trace_pixel(const Camera& camera, const RenderOptions& options, int x, int y) const override {
        return octiso::trace_pixel(tree_, placement, camera, options, x, y);
    }
    const void* typed_view() const override { return &tree_; }
    std::vector<double> x_plane(uint32_t x) const override {
        const Dims d = tree_.dims();
        std::vector<double> plane(size_t(d.y) * d.z);
        for (uint32_t z = 0; z < d.z; ++z)
            for (uint32_t y = 0; y < d.y; ++y) plane[size_t(z) * d.y + y] = double(tree_.point_locate(Coord{x, y, z}));
        return plane;
    }

private:
    std::optional<OctreeData<T>> data_;   // empty for a file step
    Octree<T> tree_;
    StepSizes sizes_;     // a built octree's
    uint32_t step_ = 0;   // a file step's
};

template <typename T>
std::shared_ptr<TypedOctree<T>> built(OctreeData<T>&& data, const Placement& placement, const BuildOptions& options) {
    auto impl = std::make_shared<TypedOctree<T>>(std::move(data));
    impl->placement = placement;
    impl->iso_range = options.iso_range;
    impl->tolerance = options.tolerance;
    impl->value_scale = options.value_scale;
    impl->flipped_axes = options.flipped_axes;
    impl->source = options.source_name;
    return impl;
}

}  // namespace

AnyOctree::AnyOctree(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

template <typename T>
AnyOctree AnyOctree::build(const VolumeView<T>& volume, const Placement& placement, const BuildOptions& options) {
    return AnyOctree(built(build_octree(volume, options), placement, options));
}

template <typename T>
AnyOctree AnyOctree::adopt(OctreeData<T>&& data, const Placement& placement, const BuildOptions& options) {
    return AnyOctree(built(std::move(data), placement, options));
}

AnyOctree AnyOctree::build(const LoadedVolume& volume, const BuildOptions& options) {
    BuildOptions named = options;
    if (named.source_name.empty()) named.source_name = volume.source();
    named.value_scale = volume.value_scale();
    named.flipped_axes = volume.flipped_axes();
    return dispatch_scalar_type(volume.type(), [&](auto tag) {
        using T = decltype(tag);
        return build(volume.view<T>(), volume.placement(), named);
    });
}

AnyOctree AnyOctree::step(std::shared_ptr<const OctFile> file, uint32_t k) {
    if (!file) throw Error("AnyOctree::step", "no file", ErrorKind::Other);
    const OctInfo& info = file->info();
    std::shared_ptr<Impl> impl = dispatch_scalar_type(info.type, [&](auto tag) -> std::shared_ptr<Impl> {
        using T = decltype(tag);
        const Octree<T> tree = file->step<T>(k);   // validates step k (once per file and step)
        return std::make_shared<TypedOctree<T>>(tree, k);
    });
    impl->placement = info.placement;
    impl->iso_range = info.iso_range;
    impl->tolerance = info.tolerance;
    impl->value_scale = info.value_scale;
    impl->flipped_axes = info.flipped_axes;
    impl->source = file->path();
    impl->file = std::move(file);
    return AnyOctree(std::move(impl));
}

AnyOctree AnyOctree::open(const std::string& path, uint32_t k, Verify verify) {
    return step(std::make_shared<const OctFile>(OctFile::open(path, verify)), k);
}

ScalarType AnyOctree::type() const { return impl_->type(); }
Dims AnyOctree::dims() const { return impl_->dims(); }
const Placement& AnyOctree::placement() const { return impl_->placement; }
int AnyOctree::dmax() const { return impl_->dmax(); }
const std::shared_ptr<const OctFile>& AnyOctree::file() const { return impl_->file; }

std::optional<std::array<double, 2>> AnyOctree::value_range() const { return impl_->value_range(); }

AnyOctreeInfo AnyOctree::info() const {
    const OctInfo header = oct_info();
    AnyOctreeInfo i;
    i.type = header.type;
    i.dims = header.dims;
    i.placement = header.placement;
    i.dmax = header.dmax;
    i.iso_range = header.iso_range;
    i.tolerance = header.tolerance;
    i.value_scale = header.value_scale;
    i.flipped_axes = header.flipped_axes;
    i.sizes = impl_->sizes();
    i.build_phases = impl_->build_phases();
    i.value_range = impl_->value_range();
    i.dense_bytes = dense_bytes();
    i.source = impl_->source;
    return i;
}

OctInfo AnyOctree::oct_info() const {
    OctInfo info;
    info.type = type();
    info.dims = dims();
    info.placement = impl_->placement;
    info.dmax = dmax();
    info.iso_range = impl_->iso_range;
    info.tolerance = impl_->tolerance;
    info.value_scale = impl_->value_scale;
    info.flipped_axes = impl_->flipped_axes;
    return info;
}

void AnyOctree::append_to(OctWriter& writer) const { impl_->append_to(writer); }

void AnyOctree::save(const std::string& path) const {
    OctWriter writer(path, oct_info());
    append_to(writer);
    writer.finish();
}

RenderLimits AnyOctree::render_limits() const { return RenderLimits{impl_->iso_range, impl_->source}; }

Renderer AnyOctree::make_renderer(const RenderOptions& options) const {
    Renderer renderer = impl_->make_renderer(options, render_limits());
    renderer.keep_alive(impl_);   // the tree's arrays (or the file's mapping) live in *impl_
    return renderer;
}

PixelTrace AnyOctree::trace_pixel(const Camera& camera, const RenderOptions& options, int x, int y) const {
    return impl_->trace_pixel(camera, options, x, y);
}

Frame AnyOctree::render(const Camera& camera, const RenderOptions& options) const {
    // Options, then camera, both before the Embree scene is made (as octiso::render() does).
    validate_options(options, render_limits());
    validate_camera(camera);
    return make_renderer(options).render(camera);
}

std::vector<double> AnyOctree::x_plane(uint32_t x) const {
    if (x >= dims().x) throw Error("x_plane", "plane " + std::to_string(x) + " outside the data", ErrorKind::Other);
    return impl_->x_plane(x);
}

uint64_t AnyOctree::dense_bytes() const { return checked_volume_bytes(dims(), type(), impl_->source); }

void AnyOctree::decode(std::span<std::byte> out, std::endian order) const {
    const uint64_t bytes = dense_bytes();
    if (out.size() != bytes)
        throw Error(impl_->source, "decode needs a buffer of " + std::to_string(bytes) + " bytes, found " +
                                       std::to_string(out.size()), ErrorKind::Other);
    impl_->decode(0, dims().z, out.data(), order != std::endian::native);
}

void AnyOctree::decode_layers(uint32_t z0, uint32_t z1, std::span<std::byte> out, std::endian order) const {
    if (z0 > z1 || z1 > dims().z)
        throw Error(impl_->source, "decode_layers: layers " + std::to_string(z0) + ".." + std::to_string(z1) +
                                       " outside 0.." + std::to_string(dims().z), ErrorKind::Other);
    const uint64_t bytes = uint64_t(dims().x) * dims().y * (z1 - z0) * scalar_type_bytes(type());
    if (out.size() != bytes)
        throw Error(impl_->source, "decode_layers needs a buffer of " + std::to_string(bytes) + " bytes, found " +
                                       std::to_string(out.size()), ErrorKind::Other);
    impl_->decode(z0, z1, out.data(), order != std::endian::native);
}

template <typename T> const Octree<T>* AnyOctree::as() const {
    return type() == scalar_type_of<T>() ? static_cast<const Octree<T>*>(impl_->typed_view()) : nullptr;
}

#define OCTISO_INSTANTIATE(T)                                                                                    \
    template AnyOctree AnyOctree::build<T>(const VolumeView<T>&, const Placement&, const BuildOptions&);        \
    template AnyOctree AnyOctree::adopt<T>(OctreeData<T>&&, const Placement&, const BuildOptions&);             \
    template const Octree<T>* AnyOctree::as<T>() const;
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso
