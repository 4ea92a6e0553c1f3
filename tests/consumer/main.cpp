// The consumer test: a program outside the octiso tree that sees only an installed octiso (public
// headers, octiso::core, octisoConfig.cmake). It builds an octree from a small array (a sphere's
// distance field), renders one frame of the isosurface at radius 5 and exits 0 only if the frame
// hit the surface. Built twice: octiso_consumer links octiso::core only; octiso_consumer_io
// (OCTISO_CONSUMER_IO) links octiso::io as well, writes the frame to the PNG named by argv[1]
// (through the installed image module) and the field to argv[1] + ".vti", which it reads back
// (through the installed volume module).
// Run by the ConsumerProject ctest test (run_consumer_test.cmake).
#include <cmath>
#include <cstdio>
#include <vector>

#include "octiso/build.h"
#include "octiso/render.h"
#include "octiso/version.h"
#ifdef OCTISO_CONSUMER_IO
#include <span>
#include <string>

#include "octiso/image.h"
#include "octiso/reader.h"
#include "octiso/volume_writer.h"
#endif

int main([[maybe_unused]] int argc, [[maybe_unused]] char** argv) {
    constexpr uint32_t n = 16;
    std::vector<float> field(size_t(n) * n * n);   // x fastest
    for (uint32_t z = 0; z < n; ++z)
        for (uint32_t y = 0; y < n; ++y)
            for (uint32_t x = 0; x < n; ++x)
                field[x + n * (y + n * z)] = float(std::hypot(x - 7.5, y - 7.5, z - 7.5));

    octiso::VolumeView<float> volume;
    volume.data = reinterpret_cast<const std::byte*>(field.data());
    volume.dims = {n, n, n};
    const octiso::OctreeData<float> octree = octiso::build_octree(volume, octiso::BuildOptions{});

    const octiso::Placement placement{};
    const octiso::Camera camera = octiso::frame_data_box(volume.dims, placement, 32, 32);
    octiso::RenderOptions options;
    options.isovalues = {5.0};
    const octiso::Frame frame = octiso::render(octree.view(), placement, camera, options);

    std::printf("octiso %s consumer: %llu of %llu rays hit\n", OCTISO_VERSION_STRING,
                static_cast<unsigned long long>(frame.stats.hits), static_cast<unsigned long long>(frame.stats.rays));
#ifdef OCTISO_CONSUMER_IO
    if (argc != 2) return 1;
    octiso::write_colour_image(argv[1], frame);
    const std::string vti = std::string(argv[1]) + ".vti";
    octiso::write_volume_file(vti, octiso::ScalarType::f32, volume.dims, placement,
                              std::as_bytes(std::span<const float>(field)));
    const octiso::LoadedVolume back = octiso::open_volume(vti, octiso::RawOptions{});
    if (back.dims().x != n || back.dims().y != n || back.dims().z != n) return 1;
#endif
    return frame.stats.hits > 0 && frame.stats.hits < frame.stats.rays ? 0 : 1;
}
