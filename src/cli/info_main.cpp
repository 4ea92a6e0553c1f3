// octiso-info: what a .oct file holds (header, sizes per step, counts per depth) and, with
// --extract-raw, the data of one step back as a raw array (CONVENTIONS 3). Every step is fully
// validated (checksums and indices) before it is reported.
#include <cerrno>
#include <cstdio>
#include <unistd.h>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <vector>

#include "cli/common/cli.h"
#include "cli/common/json.h"
#include "format/oct_layout.h"
#include "util/atomic_output.h"
#include "octiso/any_octree.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/output_guard.h"
#include "octiso/verify.h"

namespace {

using namespace octiso;

constexpr const char* kUsage =
    "usage: octiso-info FILE.oct [--json] [--verify] [--extract-raw OUT.raw [--step K] [--endian little|big]]";

struct Extract {
    std::string path;
    uint32_t step = 0;
    bool big_endian = false;
    uint64_t bytes = 0;
};

/// Decodes step `ex.step` and writes it x-fastest through AtomicOutput, byte-swapped if asked.
void extract_raw(const std::shared_ptr<const OctFile>& file, Extract& ex) {
    const OctInfo& info = file->info();
    ex.bytes = checked_volume_bytes(info.dims, info.type, file->path());
    // The dense array is decoded in memory: refuse up front, naming the size, rather than fail
    // on allocation (a sparse 16384^3 octree is 98 KB on disk and 16 TiB as an array).
    const uint64_t memory = uint64_t(::sysconf(_SC_PHYS_PAGES)) * uint64_t(::sysconf(_SC_PAGESIZE));
    if (ex.bytes > memory)
        throw Error("--extract-raw", "step " + std::to_string(ex.step) + " of " + file->path() + " is " +
                                         std::to_string(ex.bytes) + " bytes as a dense array, more than this machine's " +
                                         std::to_string(memory) + " bytes of memory");
    const AnyOctree step = AnyOctree::step(file, ex.step);
    std::vector<std::byte> data(size_t(ex.bytes));
    step.decode(data, ex.big_endian ? std::endian::big : std::endian::little);
    file->check_unchanged();   // issue 18: the decoded data came from what was validated
    write_file_atomically(ex.path, data.data(), ex.bytes);   // every write, fsync and close checked
}

std::string join(const std::vector<uint64_t>& v) {
    std::string s;
    for (size_t i = 0; i < v.size(); ++i) {
        if (i) s += ' ';
        s += std::to_string(v[i]);
    }
    return s;
}

void human_report(std::ostream& os, const OctFile& file, const std::vector<StepSizes>& steps, const Extract* ex) {
    const OctInfo& in = file.info();
    const uint64_t raw = checked_volume_bytes(in.dims, in.type, file.path()) * in.step_count;
    os << std::setprecision(10);
    os << file.path() << ": .oct format version " << format::kFormatVersion << ", header "
       << sizeof(format::FileHeader) << " bytes\n";
    os << "  type        " << scalar_type_name(in.type) << "\n";
    os << "  dims        " << in.dims.x << " x " << in.dims.y << " x " << in.dims.z << "\n";
    os << "  spacing     " << in.placement.spacing[0] << ", " << in.placement.spacing[1] << ", "
       << in.placement.spacing[2] << "\n";
    os << "  origin      " << in.placement.origin[0] << ", " << in.placement.origin[1] << ", "
       << in.placement.origin[2] << "\n";
    os << "  dmax        " << in.dmax << " (cube side " << (uint64_t(1) << in.dmax) << ")\n";
    os << "  iso-range   ";
    if (in.iso_range) os << (*in.iso_range)[0] << ", " << (*in.iso_range)[1] << "\n";
    else os << "none (every isovalue exact)\n";
    os << "  tolerance   " << in.tolerance << (in.tolerance == 0 ? " (lossless)" : "") << "\n";
    os << "  steps       " << in.step_count << "\n";
    os << "  file bytes  " << file.file_bytes() << "\n";
    os << "  raw bytes   " << raw << " (dims x " << scalar_type_bytes(in.type) << " bytes x " << in.step_count
       << " steps)\n";
    os << "  ratio       " << std::setprecision(4) << double(raw) / double(file.file_bytes()) << " : 1 (raw / file)\n"
       << std::setprecision(10);
    for (size_t k = 0; k < steps.size(); ++k) {
        const StepSizes& s = steps[k];
        os << "  step " << k << ": interior " << s.interior_bytes << " bytes (min/max " << s.minmax_bytes
           << "), caps " << s.cap_bytes << " bytes\n";
        os << "    nodes per depth          " << join(s.nodes_per_depth) << "  (last: caps)\n";
        os << "    scalar leaves per depth  " << join(s.scalar_leaves_per_depth) << "\n";
    }
    if (ex)
        os << "  extracted step " << ex->step << " to " << ex->path << " (" << ex->bytes << " bytes, "
           << (ex->big_endian ? "big" : "little") << "-endian)\n";
}

void json_report(std::ostream& os, const OctFile& file, const std::vector<StepSizes>& steps, const Extract* ex) {
    const OctInfo& in = file.info();
    const uint64_t raw_step = checked_volume_bytes(in.dims, in.type, file.path());
    const uint64_t raw = raw_step * in.step_count;
    cli::JsonWriter j(os);
    j.begin_object();
    j.field("file", file.path());
    j.field("format_version", format::kFormatVersion);
    j.field("header_bytes", sizeof(format::FileHeader));
    j.field("type", scalar_type_name(in.type));
    j.key("dims").begin_array().value(in.dims.x).value(in.dims.y).value(in.dims.z).end_array();
    j.key("spacing").array(in.placement.spacing);
    j.key("origin").array(in.placement.origin);
    j.field("dmax", in.dmax);
    j.key("iso_range");
    if (in.iso_range) j.array(*in.iso_range);
    else j.null();
    j.field("tolerance", in.tolerance);
    j.field("steps", in.step_count);
    j.field("file_bytes", file.file_bytes());
    j.field("raw_bytes_per_step", raw_step);
    j.field("raw_bytes", raw);
    j.field("ratio", double(raw) / double(file.file_bytes()));
    j.key("per_step").begin_array();
    for (size_t k = 0; k < steps.size(); ++k) {
        const StepSizes& s = steps[k];
        j.begin_object();
        j.field("step", k);
        j.field("interior_bytes", s.interior_bytes);
        j.field("minmax_bytes", s.minmax_bytes);
        j.field("cap_bytes", s.cap_bytes);
        j.key("nodes_per_depth").array(s.nodes_per_depth);
        j.key("scalar_leaves_per_depth").array(s.scalar_leaves_per_depth);
        j.end_object();
    }
    j.end_array();
    if (ex) {
        j.key("extract").begin_object();
        j.field("path", ex->path);
        j.field("step", ex->step);
        j.field("endian", ex->big_endian ? "big" : "little");
        j.field("bytes", ex->bytes);
        j.end_object();
    }
    j.end_object();
    os << "\n";
}

}  // namespace

int main(int argc, char** argv) {
    return octiso::cli::run_main("octiso-info", argc, argv, [](std::vector<std::string>& argv_rest) {
        cli::Args args(argv_rest);
        const bool json = args.flag("--json");
        const bool help = args.flag("--help") || args.flag("-h");
        const bool verify = args.flag("--verify");
        const std::optional<std::string> extract_path = args.value("--extract-raw");
        const std::optional<std::string> step_text = args.value("--step");
        const std::optional<std::string> endian_text = args.value("--endian");
        const std::vector<std::string> files = args.positional();
        args.finish();
        if (help) {
            std::cout << kUsage << "\n";
            return 0;
        }
        if (files.size() != 1)
            throw Error("", std::string(files.empty() ? "no input file" : "more than one input file") + "; " + kUsage);
        if ((step_text || endian_text) && !extract_path)
            throw Error(step_text ? "--step" : "--endian", "only makes sense with --extract-raw");
        if (extract_path) refuse_output_onto_input(*extract_path, files, "--extract-raw");   // issue 18
        Extract ex;
        if (extract_path) {
            ex.path = *extract_path;
            if (step_text) ex.step = uint32_t(cli::parse_int(*step_text, "--step", 0, UINT32_MAX));
            if (endian_text) {
                if (*endian_text != "little" && *endian_text != "big")
                    throw Error("--endian", "expected little or big, found '" + *endian_text + "'");
                ex.big_endian = *endian_text == "big";
            }
        }

        const auto shared_file = std::make_shared<const OctFile>(OctFile::open(files[0], Verify::Full));
        const OctFile& file = *shared_file;
        if (extract_path && ex.step >= file.info().step_count)
            throw Error("--step", "step " + std::to_string(ex.step) + " does not exist in " + files[0] +
                                      " (expected 0 .. " + std::to_string(file.info().step_count - 1) + ")");
        std::vector<StepSizes> steps;
        steps.reserve(file.info().step_count);
        for (uint32_t k = 0; k < file.info().step_count; ++k) steps.push_back(file.step_sizes(k));
        if (verify) {   // issue 18: every min/max and scalar recomputed from the leaves; a lie exits 2
            const VerifyStats v = verify_octree(file);
            (json ? std::cerr : std::cout) << files[0] << ": verified " << v.nodes << " interior nodes, " << v.ranges
                                           << " child ranges: every one agrees with the leaves\n";
        }
        if (extract_path) extract_raw(shared_file, ex);

        const Extract* exp = extract_path ? &ex : nullptr;
        if (json) {
            human_report(std::cerr, file, steps, exp);
            json_report(std::cout, file, steps, exp);
        } else {
            human_report(std::cout, file, steps, exp);
        }
        return 0;
    });
}
