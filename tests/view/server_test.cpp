// view/server.h over real HTTP on loopback (httplib's client against an in-process server): the
// three routes and nothing else, frames equal to the Renderer's pixels with a command line that
// reproduces their camera exactly, error replies for malformed or refused requests after which
// the server still answers, and the request-rate bound.
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>

#include <httplib.h>

#include "octiso/any_octree.h"
#include "octiso/error.h"
#include "octiso/image.h"
#include "octiso/look.h"
#include "octiso/shading.h"
#include "octiso/oct_file.h"
#include "octiso/synthetic.h"
#include "test_util/run_shell.h"
#include "test_util/scratch_dir.h"
#include "test_util/skip.h"
#include "view/png.h"
#include "view/server.h"
#include "view/session.h"

namespace octiso::view {
namespace {

/// A served sphere:24 file (one step), or one converted with an iso-range.
class ViewServerTest : public ::testing::Test {
protected:
    void start(const ServerOptions& base = {}, std::optional<std::array<double, 2>> iso_range = {},
               const std::string& synthetic = "sphere:24") {
        BuildOptions build;
        build.iso_range = iso_range;
        AnyOctree::build(make_synthetic(parse_synthetic(synthetic)), build).save(path_);
        session_ = std::make_unique<ViewSession>(path_, 2);
        ServerOptions options = base;
        options.port = 0;
        server_ = std::make_unique<ViewServer>(*session_, options);
        thread_ = std::thread([this] { server_->serve(); });
        client_ = std::make_unique<httplib::Client>("127.0.0.1", server_->bound_port());
        client_->set_keep_alive(true);
    }
    void TearDown() override {
        client_.reset();   // closes the keep-alive connection, which would hold a worker until its timeout
        if (server_) server_->stop();
        if (thread_.joinable()) thread_.join();
    }
    httplib::Result get(const std::string& target) {
        // listen_after_bind may not have started accepting yet: connections queue on the bound
        // socket, so the first request simply waits for it.
        return client_->Get(target.c_str());
    }
    test::ScratchDir dir_{"octiso_view_server"};
    std::string path_ = dir_.file("sphere.oct");
    std::unique_ptr<ViewSession> session_;
    std::unique_ptr<ViewServer> server_;
    std::thread thread_;
    std::unique_ptr<httplib::Client> client_;
};

std::array<double, 3> vec3_after(const std::string& command, const std::string& flag) {
    const size_t at = command.find(" " + flag + " ");
    EXPECT_NE(at, std::string::npos) << flag << " in " << command;
    std::istringstream words(command.substr(at + flag.size() + 2));
    std::string text;
    words >> text;
    std::array<double, 3> v{};
    const char* p = text.data();
    for (int i = 0; i < 3; ++i) {
        const auto r = std::from_chars(p, text.data() + text.size(), v[i]);
        p = r.ptr + (i < 2 ? 1 : 0);
    }
    return v;
}

TEST_F(ViewServerTest, ServesThePageAndInfo) {
    start();
    auto page = get("/");
    ASSERT_TRUE(page);
    EXPECT_EQ(page->status, 200);
    EXPECT_EQ(page->get_header_value("Content-Type"), "text/html; charset=utf-8");
    EXPECT_NE(page->body.find("<title>octiso-view</title>"), std::string::npos);
    auto info = get("/info");
    ASSERT_TRUE(info);
    EXPECT_EQ(info->status, 200);
    EXPECT_EQ(info->body, session_->info_json());
    EXPECT_NE(info->body.find("\"dims\":[24,24,24]"), std::string::npos) << info->body;
    EXPECT_NE(info->body.find("\"steps\":1"), std::string::npos) << info->body;
    EXPECT_NE(info->body.find("\"initial_iso\":null"), std::string::npos) << info->body;
    uint64_t total = 0;
    for (const uint64_t c : session_->histogram().counts) total += c;
    EXPECT_EQ(session_->histogram().counts.size(), 128u);
    EXPECT_EQ(total, 24u * 24u * 24u);   // every voxel lies within the cells' value range here
}

TEST_F(ViewServerTest, FrameIsTheRenderersImageAndItsCommandReproducesTheCamera) {
    start();
    auto res = get("/frame?iso=5.5&az=30&el=-20&zoom=1.5&w=48&h=32&seq=9");
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << res->body;
    EXPECT_EQ(res->get_header_value("Content-Type"), "image/png");
    EXPECT_EQ(res->get_header_value("X-Octiso-Seq"), "9");

    const AnyOctree tree = AnyOctree::open(path_);
    const Camera camera = orbit_camera(tree.dims(), tree.placement(), 48, 32, 30, -20, 1.5);
    RenderOptions options;
    options.isovalues = {5.5};
    const Frame expected = tree.render(camera, options);
    EXPECT_GT(expected.stats.hits, 0u);
    EXPECT_EQ(res->body, encode_png(expected)) << "same pixels through the same encoder, same bytes";

    // httplib's client percent-decodes header values itself (the page uses decodeURIComponent).
    const std::string command = res->get_header_value("X-Octiso-Command");
    EXPECT_EQ(command.rfind("octiso-render " + path_ + " --iso 5.5 ", 0), 0u) << command;
    EXPECT_EQ(vec3_after(command, "--eye"), camera.eye) << command;
    EXPECT_EQ(vec3_after(command, "--look"), camera.look) << command;
    EXPECT_EQ(vec3_after(command, "--up"), camera.up) << command;
    EXPECT_NE(command.find(" --size 48x32 -o frame.png"), std::string::npos) << command;
    EXPECT_NE(res->get_header_value("X-Octiso-Stats").find("rays=1536;hits=" + std::to_string(expected.stats.hits)),
              std::string::npos) << res->get_header_value("X-Octiso-Stats");
}

TEST_F(ViewServerTest, LevelOfDetailFramesAreTheRenderersAndTheirCommandSaysSo) {
    AnyOctree::build(make_synthetic(parse_synthetic("marschner-lobb:40")), {}).save(path_);
    session_ = std::make_unique<ViewSession>(path_, 2, std::nullopt, 8.0);   // --lod 8: far coarser than exact (no server)
    const AnyOctree tree = AnyOctree::open(path_);
    FrameRequest request;
    request.iso = 0.5, request.width = 64, request.height = 48;
    const FrameReply reply = session_->render(request);
    RenderOptions options;
    options.isovalues = {0.5};
    options.lod = 8;
    const Camera camera = session_->camera_for(request);
    const Frame expected = tree.render(camera, options);
    options.lod = 0;
    EXPECT_NE(encode_png(tree.render(camera, options)), encode_png(expected)) << "the factor coarsens this view";
    EXPECT_EQ(reply.body, encode_png(expected));
    EXPECT_NE(reply.command.find(" --iso 0.5 --lod 8 "), std::string::npos) << reply.command;
    EXPECT_THROW(ViewSession(path_, 1, std::nullopt, -1.0), Error);
}

TEST_F(ViewServerTest, RgbaFrameIsTheRenderersPixelsAsTheyAre) {
    start();
    auto res = get("/frame?iso=5.5&az=30&el=-20&zoom=1.5&w=48&h=32&seq=4&enc=rgba");
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << res->body;
    EXPECT_EQ(res->get_header_value("Content-Type"), "application/octet-stream");
    EXPECT_EQ(res->get_header_value("X-Octiso-Size"), "48x32");
    EXPECT_EQ(res->get_header_value("X-Octiso-Seq"), "4");

    const AnyOctree tree = AnyOctree::open(path_);
    const Camera camera = orbit_camera(tree.dims(), tree.placement(), 48, 32, 30, -20, 1.5);
    RenderOptions options;
    options.isovalues = {5.5};
    const Frame expected = tree.render(camera, options);   // through Embree: the viewer calls the kernel directly
    EXPECT_GT(expected.stats.hits, 0u);
    ASSERT_EQ(res->body.size(), size_t(48) * 32 * 4);
    size_t differing = 0, translucent = 0;
    for (size_t i = 0; i < size_t(48) * 32; ++i) {
        for (int c = 0; c < 3; ++c) differing += uint8_t(res->body[4 * i + c]) != expected.rgb[3 * i + c];
        translucent += uint8_t(res->body[4 * i + 3]) != 255;
    }
    EXPECT_EQ(differing, 0u);
    EXPECT_EQ(translucent, 0u);
    EXPECT_NE(res->get_header_value("X-Octiso-Stats").find(";wait="), std::string::npos) << res->get_header_value("X-Octiso-Stats");
}

TEST_F(ViewServerTest, ServesOnlyItsOwnRoutes) {
    start();
    for (const std::string target : {"/index.html", "/viewer.html", "/../etc/passwd", "/%2e%2e/etc/passwd",
                                     "/web/viewer.html", "/info/", "/frame/x", "//etc/passwd", "/CMakeLists.txt"}) {
        auto res = get(target);
        ASSERT_TRUE(res) << target;
        EXPECT_EQ(res->status, 404) << target;
        EXPECT_EQ(res->body, "not found\n") << target;
    }
    auto post = client_->Post("/frame", "iso=1", "application/x-www-form-urlencoded");
    ASSERT_TRUE(post);
    EXPECT_GE(post->status, 400);
    auto ok = get("/info");
    ASSERT_TRUE(ok);
    EXPECT_EQ(ok->status, 200);
}

TEST_F(ViewServerTest, MalformedRequestsGetAnErrorReplyAndTheServerGoesOn) {
    start();
    const std::pair<std::string, std::string> cases[] = {
        {"/frame", "iso: is required\n"},
        {"/frame?iso=abc&az=0&el=0&w=8&h=8", "iso: expected a finite decimal number, found 'abc'\n"},
        {"/frame?iso=1&az=0&el=0&w=8&h=8&file=/etc/passwd", "file: unknown parameter\n"},
        {"/frame?iso=1&az=0&el=95&w=8&h=8", "el: out of range (expected -89.000000..89.000000)\n"},
        {"/frame?iso=1&az=0&el=0&w=5000&h=8", "w: out of range (expected 1..4096, found 5000)\n"},
        {"/frame?iso=1&az=0&el=0&w=8&h=8&step=1", "step: out of range (expected 0..0, found 1)\n"},
        {"/frame?iso=%ff%00&az=0&el=0&w=8&h=8", ""},
    };
    for (const auto& [target, reply] : cases) {
        auto res = get(target);
        ASSERT_TRUE(res) << target;
        EXPECT_EQ(res->status, 400) << target;
        if (!reply.empty()) {
            EXPECT_EQ(res->body, reply) << target;
        }
    }
    auto huge = get("/frame?iso=" + std::string(20000, '1') + "&az=0&el=0&w=8&h=8");
    ASSERT_TRUE(huge);
    EXPECT_GE(huge->status, 400);   // httplib's URI bound (414) before any parsing of ours
    auto ok = get("/frame?iso=5&az=0&el=0&w=8&h=8");
    ASSERT_TRUE(ok);
    EXPECT_EQ(ok->status, 200);
}

TEST_F(ViewServerTest, IsovalueOutsideTheFilesIsoRangeIsRefused) {
    start({}, std::array<double, 2>{2.0, 10.0});
    auto res = get("/frame?iso=11&az=0&el=0&w=8&h=8");
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 422);
    EXPECT_NE(res->body.find("iso-range"), std::string::npos) << res->body;
    auto ok = get("/frame?iso=5&az=0&el=0&w=8&h=8");
    ASSERT_TRUE(ok);
    EXPECT_EQ(ok->status, 200);
}

TEST_F(ViewServerTest, InitialIsovalueIsOfferedAndCheckedAgainstTheIsoRange) {
    BuildOptions clamped;
    clamped.iso_range = std::array<double, 2>{2.0, 10.0};
    AnyOctree::build(make_synthetic(parse_synthetic("sphere:24")), clamped).save(path_);
    EXPECT_NE(ViewSession(path_, 1, 5.25).info_json().find("\"initial_iso\":5.25,"), std::string::npos);
    try {
        ViewSession(path_, 1, 11.0);
        ADD_FAILURE() << "an initial isovalue outside the file's iso-range must be refused";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("iso-range"), std::string::npos) << e.what();
    }
}

// A series: the step slider's requests render that step, and the offered command (--steps k:k with
// a frame_%04d.png pattern) makes octiso-render write the same pixels.
TEST_F(ViewServerTest, SeriesStepFrameAndItsCommandReproduceThatStep) {
    const std::string tools = OCTISO_TOOLS_DIR;
    if (!std::filesystem::exists(tools + "/octiso-render")) {
        OCTISO_SKIP("octiso-render not built");
    }
    const Dims dims{20, 18, 16};
    {
        const AnyOctree step0 = AnyOctree::build(synthetic_step("plume-series", dims, 0), BuildOptions{});
        OctWriter writer(path_, step0.oct_info());
        step0.append_to(writer);
        AnyOctree::build(synthetic_step("plume-series", dims, 1), BuildOptions{}).append_to(writer);
        writer.finish();
    }
    session_ = std::make_unique<ViewSession>(path_, 2);
    ServerOptions options;
    options.port = 0;
    server_ = std::make_unique<ViewServer>(*session_, options);
    thread_ = std::thread([this] { server_->serve(); });
    client_ = std::make_unique<httplib::Client>("127.0.0.1", server_->bound_port());
    EXPECT_NE(get("/info")->body.find("\"steps\":2"), std::string::npos);

    auto res = get("/frame?iso=40.5&az=10&el=30&w=40&h=30&step=1");
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << res->body;
    RenderOptions render_options;
    render_options.isovalues = {40.5};
    const AnyOctree step1 = AnyOctree::open(path_, 1);
    const Frame expected = step1.render(orbit_camera(dims, step1.placement(), 40, 30, 10, 30), render_options);
    EXPECT_GT(expected.stats.hits, 0u);
    EXPECT_EQ(res->body, encode_png(expected));
    const Frame step0_frame = AnyOctree::open(path_, 0).render(orbit_camera(dims, step1.placement(), 40, 30, 10, 30), render_options);
    EXPECT_NE(step0_frame.rgb, expected.rgb) << "the two steps must differ for this test to mean anything";

    std::string command = res->get_header_value("X-Octiso-Command");   // decoded by httplib
    const std::string tail = " --steps 1:1 -o frame_%04d.png";
    ASSERT_EQ(command.substr(command.size() - tail.size()), tail) << command;
    // Run it as offered: the file and the output pattern quoted for the shell, the flags as they are.
    const std::string prefix = "octiso-render " + path_ + " ";
    ASSERT_EQ(command.rfind(prefix, 0), 0u) << command;
    const std::string flags = command.substr(prefix.size(), command.size() - prefix.size() - std::string("frame_%04d.png").size());
    command = "'" + tools + "/octiso-render' '" + path_ + "' " + flags + "'" + dir_.file("frame_%04d.png") + "' 2>/dev/null";
    ASSERT_EQ(test::run_shell(command), 0) << command;
    const FloatImage written = read_image(dir_.file("frame_0001.png"));
    ASSERT_EQ(written.width, 40);
    ASSERT_EQ(written.height, 30);
    ASSERT_EQ(written.channels, 3);
    size_t differing = 0;
    for (size_t i = 0; i < expected.rgb.size(); ++i) differing += std::lround(written.pixels[i] * 255.0f) != expected.rgb[i];
    EXPECT_EQ(differing, 0u);
}

/// Runs `command` (an offered octiso-render line ending in " -o frame.png") with the tools' binary
/// and the output in `out`; returns the pixels it wrote as 8-bit RGB.
std::vector<uint8_t> run_offered(const std::string& command, const std::string& path, const std::string& out) {
    const std::string prefix = "octiso-render " + path + " ", tail = " -o frame.png";
    EXPECT_EQ(command.rfind(prefix, 0), 0u) << command;
    EXPECT_EQ(command.substr(command.size() - tail.size()), tail) << command;
    const std::string flags = command.substr(prefix.size(), command.size() - prefix.size() - tail.size());
    const std::string line = "'" + std::string(OCTISO_TOOLS_DIR) + "/octiso-render' '" + path + "' " + flags + " -o '" + out + "' 2>/dev/null";
    EXPECT_EQ(test::run_shell(line), 0) << line;
    const FloatImage written = read_image(out);
    std::vector<uint8_t> rgb(written.pixels.size());
    for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t(std::lround(written.pixels[i] * 255.0f));
    return rgb;
}

// Shadows and AO (issue 20 after issue 17 item 7): the frame is the light kit through LookShader
// over the Renderer's AOVs, as octiso-render --shadows --ao N renders it, and the offered command
// (which carries those flags) writes the same pixels. Marschner-Lobb's lobes cast shadows on each
// other, so the shadows visibly change the frame.
TEST_F(ViewServerTest, ShadowsAndAoFrameIsTheLookShadersAndItsCommandReproducesIt) {
    if (!std::filesystem::exists(std::string(OCTISO_TOOLS_DIR) + "/octiso-render")) {
        OCTISO_SKIP("octiso-render not built");
    }
    start({}, {}, "marschner-lobb:32");
    const AnyOctree tree = AnyOctree::open(path_);
    const Camera camera = orbit_camera(tree.dims(), tree.placement(), 48, 40, 30, 35, 1.3);
    RenderOptions options;
    options.isovalues = {0.5};
    options.want_colour = false, options.want_depth = options.want_normal = true;
    const auto look_frame = [&](bool shadows, int ao) {
        Frame f = tree.render(camera, options);
        Look look;
        look.shadows = shadows, look.ao_samples = ao;
        if (look.active()) LookShader(tree, options, look, ShadingModel::kit).shade(camera, Shading{}, f);
        else shade_frame(tree, options.isovalues, camera, Shading{}, f);   // the kit without secondary rays
        return f;
    };
    const Frame kit = look_frame(false, 0);
    for (const auto& [shadows, ao] : {std::pair{true, 0}, {false, 8}, {true, 8}}) {
        const std::string what = std::string(shadows ? "shadows" : "") + (ao ? " ao " + std::to_string(ao) : "");
        auto res = get("/frame?iso=0.5&az=30&el=35&zoom=1.3&w=48&h=40&shadows=" + std::string(shadows ? "1" : "0") +
                       "&ao=" + std::to_string(ao));
        ASSERT_TRUE(res) << what;
        ASSERT_EQ(res->status, 200) << what << ": " << res->body;
        const Frame expected = look_frame(shadows, ao);
        EXPECT_GT(expected.stats.hits, 200u) << what;
        EXPECT_EQ(res->body, encode_png(expected)) << what << ": the LookShader's pixels";
        EXPECT_NE(expected.rgb, kit.rgb) << what << ": the look must change the frame for this test to mean anything";
        const std::string stats = res->get_header_value("X-Octiso-Stats");
        EXPECT_EQ(stats.find(";secondary=0"), std::string::npos) << what << ": " << stats;

        const std::string command = res->get_header_value("X-Octiso-Command");
        EXPECT_EQ(command.find("--shading"), std::string::npos) << what << ": the kit is octiso-render's default: " << command;
        EXPECT_EQ(command.find(" --shadows ") != std::string::npos, shadows) << command;
        EXPECT_EQ(command.find(" --ao 8 ") != std::string::npos, ao == 8) << command;
        const std::vector<uint8_t> written = run_offered(command, path_, dir_.file("look.png"));
        ASSERT_EQ(written.size(), expected.rgb.size()) << what;
        size_t differing = 0;
        for (size_t i = 0; i < written.size(); ++i) differing += written[i] != expected.rgb[i];
        EXPECT_EQ(differing, 0u) << what << ": " << command;
    }
    // Another isovalue with the same look: the session's LookShader (made for 0.5) is remade.
    auto other = get("/frame?iso=0.4&az=30&el=35&zoom=1.3&w=48&h=40&shadows=1&ao=8");
    ASSERT_TRUE(other);
    options.isovalues = {0.4};
    EXPECT_EQ(other->body, encode_png(look_frame(true, 8)));
    options.isovalues = {0.5};
    // Both off again: back to the Renderer's own colour and --shading headlight.
    auto plain = get("/frame?iso=0.5&az=30&el=35&zoom=1.3&w=48&h=40&shadows=0&ao=0");
    ASSERT_TRUE(plain);
    RenderOptions headlight;
    headlight.isovalues = {0.5};
    EXPECT_EQ(plain->body, encode_png(tree.render(camera, headlight)));
    EXPECT_NE(plain->get_header_value("X-Octiso-Command").find(" --shading headlight "), std::string::npos);
    EXPECT_NE(plain->get_header_value("X-Octiso-Stats").find(";look=0.000000;secondary=0"), std::string::npos);
    auto bad = get("/frame?iso=0.5&az=30&el=35&w=8&h=8&ao=17");
    ASSERT_TRUE(bad);
    EXPECT_EQ(bad->status, 400);
    EXPECT_EQ(bad->body, "ao: out of range (expected 0..16, found 17)\n");
}

TEST_F(ViewServerTest, RequestsBeyondTheRateBoundAreRefused) {
    ServerOptions options;
    options.rate_capacity = 3;
    options.rate_per_second = 1e-9;   // no refill within the test
    start(options);
    for (int i = 0; i < 3; ++i) {
        auto res = get("/info");
        ASSERT_TRUE(res);
        EXPECT_EQ(res->status, 200) << i;
    }
    auto refused = get("/info");
    ASSERT_TRUE(refused);
    EXPECT_EQ(refused->status, 429);
    EXPECT_EQ(refused->body, "too many requests\n");
}

}  // namespace
}  // namespace octiso::view
