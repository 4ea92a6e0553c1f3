// The volume codec module, liboctiso_volumes.so (volume_codec.h says why it is a module): every
// use octiso makes of VTK's readers and writers. Nothing links it; octiso_io loads it the first
// time a file needs VTK (volume_codec_loader.h).
//
// Reading: VTK reports failures through events and its output window rather than exceptions, so
// every read runs with an error observer and a silent, capturing output window, and the output is
// checked (dims, one component, array length) before anyone trusts it. The scalar array stays
// alive inside the returned owner: no copy of the voxels is made. (The io side checked the file
// itself and its declared size first: bad datatypes crash VTK, short data is zero-filled.)
// Writing: .vti through VTK's XML writer, NIfTI-1 through vtkNIFTIImageWriter, each into a
// temporary the io side renames (volume_writer.cpp).
#include <iostream>
#include <new>
#include <optional>
#include <stdexcept>
#include <mutex>
#include <sstream>
#include <string>

#include <vtkAlgorithm.h>
#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkLogger.h>
#include <vtkMatrix4x4.h>
#include <vtkMetaImageReader.h>
#include <vtkNIFTIImageReader.h>
#include <vtkNIFTIImageWriter.h>
#include <vtkNew.h>
#include <vtkNrrdReader.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkStructuredPointsReader.h>
#include <vtkType.h>
#include <vtkXMLImageDataReader.h>
#include <vtkXMLImageDataWriter.h>

#include "io/volume_codec.h"
#include "octiso/error.h"

namespace octiso::volume_codec {
namespace {

// Messages VTK routes to its output window (objects without an ErrorEvent observer, such as the
// XML parser inside a reader) land here instead of on stderr: the library never prints.
thread_local std::string t_vtk_window_text;

class CapturingOutputWindow : public vtkOutputWindow {
public:
    static CapturingOutputWindow* New();
    vtkTypeMacro(CapturingOutputWindow, vtkOutputWindow)
    void DisplayText(const char* text) override { capture(text); }
    void DisplayErrorText(const char* text) override { capture(text); }
    void DisplayWarningText(const char*) override {}
    void DisplayGenericWarningText(const char*) override {}
    void DisplayDebugText(const char*) override {}

private:
    static void capture(const char* text) {
        if (text && t_vtk_window_text.empty()) t_vtk_window_text = text;
    }
};
vtkStandardNewMacro(CapturingOutputWindow);

// Process-wide and once: VTK has a single output window and a single logger. Errors still reach
// observers (and our window); only VTK's own printing is switched off.
void silence_vtk() {
    static std::once_flag once;
    std::call_once(once, [] {
        vtkSmartPointer<CapturingOutputWindow> w = vtkSmartPointer<CapturingOutputWindow>::New();
        vtkOutputWindow::SetInstance(w);
        vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
    });
}

// MetaIO (inside vtkMetaImageReader) writes its complaints straight to std::cout/std::cerr.
// Swapping the stream buffers is not thread-safe for other printers, but readers run before any
// worker thread starts, and the library must not print.
class StdStreamsMuted {
public:
    StdStreamsMuted() : out_(std::cout.rdbuf(sink_.rdbuf())), err_(std::cerr.rdbuf(sink_.rdbuf())) {}
    ~StdStreamsMuted() {
        std::cout.rdbuf(out_);
        std::cerr.rdbuf(err_);
    }

private:
    std::ostringstream sink_;
    std::streambuf* out_;
    std::streambuf* err_;
};

// First ErrorEvent text raised on the reader itself.
struct ErrorCatcher {
    std::string text;
    static void on_error(vtkObject*, unsigned long, void* client, void* call) {
        auto* self = static_cast<ErrorCatcher*>(client);
        if (self->text.empty() && call) self->text = static_cast<const char*>(call);
    }
};

// VTK's text is "ERROR: In FILE, line N\nClass (0x...): message\n\n": keep the message line.
std::string clean_vtk_message(std::string text) {
    if (text.rfind("ERROR: In ", 0) == 0 || text.rfind("Warning: In ", 0) == 0) {
        const size_t nl = text.find('\n');
        text = nl == std::string::npos ? std::string() : text.substr(nl + 1);
    }
    const size_t paren = text.find(" (0x");
    const size_t close = text.find("): ");
    if (paren != std::string::npos && close != std::string::npos && paren < close && text.find(' ') == paren)
        text = text.substr(close + 3);
    const size_t nl = text.find('\n');
    if (nl != std::string::npos) text.resize(nl);
    while (!text.empty() && (text.back() == ' ' || text.back() == '\r' || text.back() == '.')) text.pop_back();
    return text.empty() ? "VTK reported an error" : text;
}

std::optional<ScalarType> scalar_type_from_vtk(int vtk_type) {
    switch (vtk_type) {
        case VTK_UNSIGNED_CHAR: return ScalarType::u8;
        case VTK_CHAR:
        case VTK_SIGNED_CHAR: return ScalarType::i8;
        case VTK_UNSIGNED_SHORT: return ScalarType::u16;
        case VTK_SHORT: return ScalarType::i16;
        case VTK_UNSIGNED_INT: return ScalarType::u32;
        case VTK_INT: return ScalarType::i32;
        case VTK_FLOAT: return ScalarType::f32;
        case VTK_DOUBLE: return ScalarType::f64;
        default: return std::nullopt;
    }
}

template <class Reader> vtkSmartPointer<vtkAlgorithm> reader_of(const std::string& path) {
    auto r = vtkSmartPointer<Reader>::New();
    r->SetFileName(path.c_str());
    return r;
}

vtkSmartPointer<vtkAlgorithm> make_reader(VolumeFormat format, const std::string& path) {
    switch (format) {
        case VolumeFormat::nifti: return reader_of<vtkNIFTIImageReader>(path);
        case VolumeFormat::vti: return reader_of<vtkXMLImageDataReader>(path);
        case VolumeFormat::legacy_vtk: return reader_of<vtkStructuredPointsReader>(path);
        case VolumeFormat::meta_image: return reader_of<vtkMetaImageReader>(path);
        case VolumeFormat::nrrd: return reader_of<vtkNrrdReader>(path);
        default: break;
    }
    throw Error(path, "not a VTK-readable format", ErrorKind::Other);
}

// Runs the reader (the whole read, or the header only) with both of VTK's error channels captured;
// the first message becomes Error(path, what + message).
void run_captured(vtkAlgorithm* reader, VolumeFormat format, const std::string& path, const std::string& what,
                  bool information_only) {
    ErrorCatcher catcher;
    auto callback = vtkSmartPointer<vtkCallbackCommand>::New();
    callback->SetCallback(&ErrorCatcher::on_error);
    callback->SetClientData(&catcher);
    reader->AddObserver(vtkCommand::ErrorEvent, callback);
    t_vtk_window_text.clear();
    {
        std::optional<StdStreamsMuted> muted;
        if (format == VolumeFormat::meta_image) muted.emplace();
        try {
            if (information_only) reader->UpdateInformation();
            else reader->Update();
        } catch (const std::bad_alloc&) {
            throw Error(path, what + "out of memory reading the voxels the header declares");
        } catch (const std::length_error&) {
            throw Error(path, what + "the header declares more voxels than can be allocated");
        }
    }
    const std::string window_text = std::move(t_vtk_window_text);
    t_vtk_window_text.clear();
    if (!catcher.text.empty()) throw Error(path, what + clean_vtk_message(catcher.text));
    if (!window_text.empty()) throw Error(path, what + clean_vtk_message(window_text));
    if (reader->GetErrorCode() != 0) throw Error(path, what + "VTK error code " + std::to_string(reader->GetErrorCode()));
}

/// Voxel (0,0,0) of our grid is the extent's lower corner, not VTK's index 0.
Placement placement_of(const double* spacing, const double* origin, const int* extent) {
    Placement placement;
    for (int a = 0; a < 3; ++a) {
        placement.spacing[size_t(a)] = spacing[a];
        placement.origin[size_t(a)] = origin[a] + extent[2 * a] * spacing[a];
    }
    return placement;
}

/// read_vtk (reader.h) after the io side's checks of the file (check_input_file, check_declared_size).
ReadVolume read_volume(const std::string& path, VolumeFormat format, const std::string* array) {
    silence_vtk();
    const std::string what = "cannot read as " + std::string(volume_format_name(format)) + ": ";

    vtkSmartPointer<vtkAlgorithm> reader = make_reader(format, path);
    if (format == VolumeFormat::legacy_vtk) {
        // The legacy reader happily "reads" polydata or grids as empty image data.
        auto* legacy = static_cast<vtkStructuredPointsReader*>(reader.GetPointer());
        if (!legacy->IsFileStructuredPoints())
            throw Error(path, what + "not a legacy VTK STRUCTURED_POINTS file");
        if (array) legacy->ReadAllScalarsOn();   // else only the first SCALARS block is read
    }

    // 1. Run the reader with both error channels captured.
    run_captured(reader, format, path, what, /*information_only=*/false);

    // 2. The output must be one complete single-component image.
    vtkImageData* image = vtkImageData::SafeDownCast(reader->GetOutputDataObject(0));
    if (!image) throw Error(path, what + "no image data in the file");
    vtkPointData* point_data = image->GetPointData();
    vtkDataArray* scalars = nullptr;
    if (array) {
        scalars = point_data->GetArray(array->c_str());
        if (!scalars) {
            std::string names;
            for (int i = 0; i < point_data->GetNumberOfArrays(); ++i) {
                const char* name = point_data->GetArrayName(i);
                names += std::string(i ? ", " : "") + "'" + (name ? name : "") + "'";
            }
            throw Error(path, "has no point data array '" + *array + "' (--array; arrays in the file: " +
                                  (names.empty() ? std::string("none") : names) + ")");
        }
    } else {
        scalars = point_data->GetScalars();
        if (!scalars && point_data->GetNumberOfArrays() > 0) scalars = point_data->GetArray(0);
    }
    if (!scalars) throw Error(path, what + "no point data array (cell data is not supported)");
    if (scalars->GetNumberOfComponents() != 1) {
        // VTK's NRRD reader takes a fastest axis of 9 or fewer samples for vector components.
        const std::string hint = format == VolumeFormat::nifti ? " (a 4-D NIfTI's time points become components)"
                               : format == VolumeFormat::nrrd  ? " (VTK reads a first NRRD axis of 9 or fewer samples as components)"
                                                               : "";
        throw Error(path, "has " + std::to_string(scalars->GetNumberOfComponents()) +
                              " components per voxel; octiso needs exactly one" + hint);
    }
    const std::optional<ScalarType> type = scalar_type_from_vtk(scalars->GetDataType());
    if (!type)
        throw Error(path, std::string("scalar type ") + scalars->GetDataTypeAsString() +
                              " is not supported (expected one of u8 i8 u16 i16 u32 i32 f32 f64)");
    int dim[3] = {0, 0, 0};
    image->GetDimensions(dim);
    for (int a = 0; a < 3; ++a)
        if (dim[a] < 1 || uint64_t(dim[a]) > Dims::kMaxExtent)
            throw Error(path, what + "image dimensions " + std::to_string(dim[0]) + "x" + std::to_string(dim[1]) +
                                  "x" + std::to_string(dim[2]) + " are empty or too large");
    const Dims dims{uint32_t(dim[0]), uint32_t(dim[1]), uint32_t(dim[2])};
    checked_volume_bytes(dims, *type, path);
    if (uint64_t(scalars->GetNumberOfTuples()) != dims.voxels())
        throw Error(path, what + "array holds " + std::to_string(scalars->GetNumberOfTuples()) +
                              " values (expected " + std::to_string(dims.voxels()) + ")");
    if (!scalars->HasStandardMemoryLayout())
        throw Error(path, what + "array is not stored contiguously", ErrorKind::Other);

    // 3. Placement.
    const Placement placement = placement_of(image->GetSpacing(), image->GetOrigin(), image->GetExtent());

    // 4. Keep only the array alive; the reader and image go when this function returns.
    scalars->Register(nullptr);
    std::shared_ptr<const void> owner(scalars, [](const void* p) {
        static_cast<vtkDataArray*>(const_cast<void*>(p))->UnRegister(nullptr);
    });
    const auto* data = static_cast<const std::byte*>(scalars->GetVoidPointer(0));
    return ReadVolume{std::move(owner), data, *type, dims, placement};
}

/// read_vtk_information (vtk_information.h) after the io side's checks of the file.
io::VtkImageInformation read_information_of(const std::string& path, VolumeFormat format) {
    silence_vtk();
    const std::string what = "cannot read as " + std::string(volume_format_name(format)) + ": ";
    vtkSmartPointer<vtkAlgorithm> reader = make_reader(format, path);
    run_captured(reader, format, path, what, /*information_only=*/true);
    vtkInformation* info = reader->GetOutputInformation(0);
    if (!info || !info->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
        throw Error(path, what + "no image extent in the header");
    int extent[6];
    info->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent);
    double spacing[3] = {1, 1, 1}, origin[3] = {0, 0, 0};
    if (info->Has(vtkDataObject::SPACING())) info->Get(vtkDataObject::SPACING(), spacing);
    if (info->Has(vtkDataObject::ORIGIN())) info->Get(vtkDataObject::ORIGIN(), origin);
    io::VtkImageInformation r;
    for (int a = 0; a < 3; ++a) {
        const int64_t n = int64_t(extent[2 * a + 1]) - extent[2 * a] + 1;
        r.extent[size_t(a)] = n < 0 ? 0 : uint64_t(n);
    }
    r.type = scalar_type_from_vtk(vtkImageData::GetScalarType(info));
    r.components = vtkImageData::GetNumberOfScalarComponents(info);
    r.placement = placement_of(spacing, origin, extent);
    return r;
}


int vtk_type_of(ScalarType t) {
    switch (t) {
        case ScalarType::u8: return VTK_UNSIGNED_CHAR;
        case ScalarType::i8: return VTK_SIGNED_CHAR;
        case ScalarType::u16: return VTK_UNSIGNED_SHORT;
        case ScalarType::i16: return VTK_SHORT;
        case ScalarType::u32: return VTK_UNSIGNED_INT;
        case ScalarType::i32: return VTK_INT;
        case ScalarType::f32: return VTK_FLOAT;
        case ScalarType::f64: break;
    }
    return VTK_DOUBLE;
}

/// vtkImageData over the request's voxels without a copy (the writers only read them).
vtkSmartPointer<vtkImageData> image_over(const WriteRequest& r) {
    auto image = vtkSmartPointer<vtkImageData>::New();
    image->SetDimensions(int(r.dims.x), int(r.dims.y), int(r.dims.z));
    vtkSmartPointer<vtkDataArray> array = vtkSmartPointer<vtkDataArray>::Take(vtkDataArray::CreateDataArray(vtk_type_of(r.type)));
    array->SetNumberOfComponents(1);
    array->SetName("scalars");
    // save = 1: VTK never frees memory it does not own.
    array->SetVoidArray(const_cast<std::byte*>(r.data.data()), vtkIdType(r.dims.voxels()), 1);
    image->GetPointData()->SetScalars(array);
    return image;
}

bool write_vti_file(const std::string& file, const WriteRequest& r) {
    vtkSmartPointer<vtkImageData> image = image_over(r);
    const Placement& p = r.placement;
    image->SetSpacing(p.spacing[0], p.spacing[1], p.spacing[2]);
    image->SetOrigin(p.origin[0], p.origin[1], p.origin[2]);
    vtkNew<vtkXMLImageDataWriter> writer;
    writer->SetFileName(file.c_str());
    writer->SetInputData(image);
    writer->SetDataModeToAppended();
    writer->SetCompressorTypeToZLib();
    return writer->Write() == 1 && writer->GetErrorCode() == 0;
}

/// NIfTI-1 in the source file's order (the request's voxels already are): voxel (i,j,k) of the
/// file sits at srow * (i,j,k,1) with srow = diag(+-spacing) and, on a reversed axis, the far end
/// of the tree's box as its translation, which is what the reader turned round (CONVENTIONS 2b).
bool write_nifti_file(const std::string& file, const WriteRequest& r) {
    vtkSmartPointer<vtkImageData> image = image_over(r);
    const Placement& p = r.placement;
    // The writer scales the sform's columns by the spacing and keeps the image origin out of it.
    image->SetSpacing(p.spacing[0], p.spacing[1], p.spacing[2]);
    image->SetOrigin(0, 0, 0);
    const uint32_t n[3] = {r.dims.x, r.dims.y, r.dims.z};
    vtkNew<vtkMatrix4x4> sform;
    for (int a = 0; a < 3; ++a) {
        const bool reversed = r.flipped_axes & (1u << a);
        sform->SetElement(a, a, reversed ? -1.0 : 1.0);
        sform->SetElement(a, 3, reversed ? p.origin[size_t(a)] + p.spacing[size_t(a)] * double(n[a] - 1) : p.origin[size_t(a)]);
    }
    vtkNew<vtkNIFTIImageWriter> writer;
    writer->SetFileName(file.c_str());   // gzip where the name ends in .gz
    writer->SetInputData(image);
    writer->SetSFormMatrix(sform);
    if (!r.flipped_axes) {
        // A qform too (a rotation, so only without reversed axes): readers that prefer it agree.
        vtkNew<vtkMatrix4x4> qform;
        for (int a = 0; a < 3; ++a) qform->SetElement(a, 3, p.origin[size_t(a)]);
        writer->SetQFormMatrix(qform);
    }
    if (!r.scale.is_identity()) {
        writer->SetRescaleSlope(r.scale.slope);
        writer->SetRescaleIntercept(r.scale.inter);
    }
    writer->SetDescription("octiso-info --extract");
    writer->Write();
    return writer->GetErrorCode() == 0;
}

/// Runs `f`, turning what it throws into a Failure: the problem of an octiso::Error (the io side
/// names the file again), anything else as a failure of the library.
template <class F> Failure captured(F&& f) {
    try {
        f();
        return {};
    } catch (const Error& e) {
        return Failure{e.problem(), e.kind() == ErrorKind::Other};
    } catch (const std::bad_alloc&) {
        return Failure{"out of memory in VTK", true};
    } catch (const std::exception& e) {
        return Failure{std::string("VTK failed: ") + e.what(), true};
    }
}

Failure entry_read(const std::string& path, VolumeFormat format, const std::string* array, ReadVolume& out) {
    return captured([&] { out = read_volume(path, format, array); });
}
Failure entry_read_information(const std::string& path, VolumeFormat format, io::VtkImageInformation& out) {
    return captured([&] { out = read_information_of(path, format); });
}
Failure entry_write_vti(const std::string& file, const WriteRequest& request) {
    return captured([&] {
        if (!write_vti_file(file, request)) throw Error(file, "VTK's image writer failed", ErrorKind::Other);
    });
}
Failure entry_write_nifti(const std::string& file, const WriteRequest& request) {
    return captured([&] {
        if (!write_nifti_file(file, request)) throw Error(file, "VTK's NIfTI writer failed", ErrorKind::Other);
    });
}

constexpr VolumeCodec kCodec{kVolumeCodecAbi, entry_read, entry_read_information, entry_write_vti, entry_write_nifti};

}  // namespace
}  // namespace octiso::volume_codec

extern "C" __attribute__((visibility("default"))) const octiso::volume_codec::VolumeCodec* octiso_volume_codec() {
    return &octiso::volume_codec::kCodec;
}
