// --array NAME (issue 17 item 3; RawOptions::array, src/io/vtk_reader.cpp): one point data array
// of a VTK file with several, written here by VTK's own writers (.vti and legacy .vtk); the
// default stays the active scalars; an unknown name is refused listing the arrays there; the
// flag is refused for formats that hold one array (raw, NIfTI) and by the tool with exit 2.
#include <gtest/gtest.h>

#if __has_include(<vtkXMLImageDataWriter.h>)
#include <filesystem>

#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkStructuredPointsWriter.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLImageDataWriter.h>

#include "cli/cli_test_util.h"
#include "octiso/error.h"
#include "octiso/reader.h"
#include "test_util/scratch_dir.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

constexpr int kNx = 6, kNy = 4, kNz = 3, kN = kNx * kNy * kNz;

/// density (u8, the active scalars) = i % 200, temperature (f32) = 0.5 * i - 7.
vtkSmartPointer<vtkImageData> two_arrays() {
    auto image = vtkSmartPointer<vtkImageData>::New();
    image->SetDimensions(kNx, kNy, kNz);
    image->SetSpacing(0.5, 1, 2);
    auto density = vtkSmartPointer<vtkUnsignedCharArray>::New();
    density->SetName("density");
    auto temperature = vtkSmartPointer<vtkFloatArray>::New();
    temperature->SetName("temperature");
    for (int i = 0; i < kN; ++i) {
        density->InsertNextValue(static_cast<unsigned char>(i % 200));
        temperature->InsertNextValue(0.5f * float(i) - 7);
    }
    image->GetPointData()->SetScalars(density);
    image->GetPointData()->AddArray(temperature);
    return image;
}

std::vector<std::string> written_files(ScratchDir& dir) {
    const auto image = two_arrays();
    auto xml = vtkSmartPointer<vtkXMLImageDataWriter>::New();
    xml->SetInputData(image);
    xml->SetFileName(dir.file("two.vti").c_str());
    xml->Write();
    auto legacy = vtkSmartPointer<vtkStructuredPointsWriter>::New();
    legacy->SetInputData(image);
    legacy->SetFileName(dir.file("two.vtk").c_str());
    legacy->Write();
    return {dir.file("two.vti"), dir.file("two.vtk")};
}

TEST(ArrayOption, PicksTheNamedArrayAndDefaultsToTheActiveScalars) {
    ScratchDir dir("array_option");
    for (const std::string& path : written_files(dir)) {
        SCOPED_TRACE(path);
        const LoadedVolume d = open_volume(path, {});
        ASSERT_EQ(d.type(), ScalarType::u8);
        RawOptions pick;
        pick.array = "temperature";
        const LoadedVolume t = open_volume(path, pick);
        ASSERT_EQ(t.type(), ScalarType::f32);
        EXPECT_EQ(t.dims(), (Dims{kNx, kNy, kNz}));
        EXPECT_EQ(t.placement().spacing, (std::array<double, 3>{0.5, 1, 2}));
        const VolumeView<float> v = t.view<float>();
        for (int i = 0; i < kN; ++i) ASSERT_EQ(v.load(uint64_t(i)), 0.5f * float(i) - 7) << i;
        pick.array = "density";
        EXPECT_EQ(open_volume(path, pick).type(), ScalarType::u8);
    }
}

TEST(ArrayOption, UnknownNameListsTheArrays) {
    ScratchDir dir("array_unknown");
    for (const std::string& path : written_files(dir)) {
        RawOptions pick;
        pick.array = "pressure";
        try {
            open_volume(path, pick);
            ADD_FAILURE() << path << ": accepted";
        } catch (const Error& e) {
            EXPECT_EQ(e.exit_status(), 2);
            EXPECT_EQ(e.subject(), path);
            EXPECT_NE(std::string(e.what()).find("no point data array 'pressure'"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("'density', 'temperature'"), std::string::npos) << e.what();
        }
    }
}

TEST(ArrayOption, RefusedWhereTheFormatHoldsOneArray) {
    ScratchDir dir("array_single");
    const std::string raw = dir.file("v.raw");
    write_raw(raw, std::vector<uint8_t>(8, 1));
    RawOptions o;
    o.dims = Dims{2, 2, 2};
    o.type = ScalarType::u8;
    o.array = "x";
    try {
        open_volume(raw, o);
        ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.subject(), "--array");
    }
}

TEST(ArrayOption, ToolPicksOrRefusesInOneLine) {
    if (!std::filesystem::exists(std::string(OCTISO_TOOLS_DIR) + "/octiso-convert")) { OCTISO_SKIP("octiso-convert not built"); }
    ScratchDir dir("array_cli");
    const std::string vti = written_files(dir)[0];
    const ToolRun ok = run_tool("octiso-convert", "'" + vti + "' --array temperature -o '" + dir.file("t.oct") + "' --json");
    ASSERT_EQ(ok.status, 0) << ok.err;
    EXPECT_NE(ok.out.find("\"type\":\"f32\""), std::string::npos) << ok.out;
    EXPECT_EQ(json_numbers(ok.out, "value_range"), (std::vector<double>{-7, 0.5 * (kN - 1) - 7}));
    const ToolRun bad = run_tool("octiso-convert", "'" + vti + "' --array pressure -o '" + dir.file("p.oct") + "'");
    EXPECT_EQ(bad.status, 2);
    EXPECT_EQ(bad.err_lines(), 1) << bad.err;
    EXPECT_NE(bad.err.find("'density', 'temperature'"), std::string::npos) << bad.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("p.oct")));
}

}  // namespace
}  // namespace octiso::test
#endif
