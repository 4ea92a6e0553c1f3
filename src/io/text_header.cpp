#include "io/text_header.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>

#include <sys/stat.h>

#include "octiso/error.h"

namespace octiso::io {

std::string header_bytes(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::string s(kTextHeaderLimit, '\0');
    f.read(s.data(), std::streamsize(s.size()));
    s.resize(size_t(f.gcount()));
    return s;
}

std::string lower_case(std::string s) {
    for (char& c : s) c = char(std::tolower((unsigned char)c));
    return s;
}

std::string trimmed(std::string s) {
    while (!s.empty() && std::isspace((unsigned char)s.back())) s.pop_back();
    size_t i = 0;
    while (i < s.size() && std::isspace((unsigned char)s[i])) ++i;
    return s.substr(i);
}

uint64_t regular_file_size(const std::string& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) ? uint64_t(st.st_size) : 0;
}

TextHeader parse_nrrd_header(const std::string& path) {
    const std::string head = header_bytes(path);
    size_t end = head.find("\n\n");
    size_t skip = 2;
    if (const size_t crlf = head.find("\r\n\r\n"); crlf != std::string::npos && crlf < end) end = crlf, skip = 4;
    TextHeader h;
    if (end != std::string::npos) h.data_offset = uint64_t(end + skip);
    std::istringstream lines(head.substr(0, end == std::string::npos ? head.size() : end));
    std::string line;
    while (std::getline(lines, line)) {
        if (line.empty() || line[0] == '#') continue;
        const size_t colon = line.find(':');
        if (colon == std::string::npos) continue;
        std::string key = lower_case(trimmed(line.substr(0, colon)));
        std::string value = line.substr(colon + 1);
        if (!value.empty() && value[0] == '=') continue;   // key:=value pairs
        key.erase(std::remove(key.begin(), key.end(), ' '), key.end());
        h.field[key] = trimmed(value);
    }
    return h;
}

TextHeader parse_meta_image_header(const std::string& path) {
    const std::string head = header_bytes(path);
    std::istringstream in(head);
    std::string line;
    TextHeader h;
    while (std::getline(in, line)) {
        const size_t eq = line.find('=');
        if (eq == std::string::npos) continue;
        const std::string key = trimmed(line.substr(0, eq));
        h.field[key] = trimmed(line.substr(eq + 1));
        if (key == "ElementDataFile") {
            // -1 where the line ran to the end of the bytes read: no data follows, or the
            // header is longer than the limit.
            if (const std::streamoff at = in.tellg(); at >= 0) h.data_offset = uint64_t(at);
            break;
        }
    }
    return h;
}

int nrrd_type_bytes(const std::string& t) {
    static const std::map<std::string, int> types = {
        {"signed char", 1}, {"int8", 1}, {"int8_t", 1}, {"uchar", 1}, {"unsigned char", 1}, {"uint8", 1}, {"uint8_t", 1},
        {"short", 2}, {"short int", 2}, {"signed short", 2}, {"signed short int", 2}, {"int16", 2}, {"int16_t", 2},
        {"ushort", 2}, {"unsigned short", 2}, {"unsigned short int", 2}, {"uint16", 2}, {"uint16_t", 2},
        {"int", 4}, {"signed int", 4}, {"int32", 4}, {"int32_t", 4}, {"uint", 4}, {"unsigned int", 4}, {"uint32", 4},
        {"uint32_t", 4}, {"longlong", 8}, {"long long", 8}, {"long long int", 8}, {"signed long long", 8},
        {"signed long long int", 8}, {"int64", 8}, {"int64_t", 8}, {"ulonglong", 8}, {"unsigned long long", 8},
        {"unsigned long long int", 8}, {"uint64", 8}, {"uint64_t", 8}, {"float", 4}, {"double", 8}};
    const auto it = types.find(lower_case(t));
    return it == types.end() ? 0 : it->second;
}

std::optional<ScalarType> nrrd_scalar_type(const std::string& t) {
    const std::string n = lower_case(t);
    if (n == "float") return ScalarType::f32;
    if (n == "double") return ScalarType::f64;
    const int bytes = nrrd_type_bytes(n);
    if (bytes == 0 || bytes == 8) return std::nullopt;
    const bool is_unsigned = n.find("unsigned") != std::string::npos || n.rfind("uint", 0) == 0 ||
                             n == "uchar" || n == "ushort" || n == "uint";
    switch (bytes) {
        case 1: return is_unsigned ? ScalarType::u8 : ScalarType::i8;
        case 2: return is_unsigned ? ScalarType::u16 : ScalarType::i16;
        default: return is_unsigned ? ScalarType::u32 : ScalarType::i32;
    }
}

int meta_image_type_bytes(const std::string& t) {
    static const std::map<std::string, int> types = {
        {"MET_UCHAR", 1}, {"MET_CHAR", 1}, {"MET_USHORT", 2}, {"MET_SHORT", 2}, {"MET_UINT", 4}, {"MET_INT", 4},
        {"MET_ULONG", 8}, {"MET_LONG", 8}, {"MET_ULONG_LONG", 8}, {"MET_LONG_LONG", 8}, {"MET_FLOAT", 4}, {"MET_DOUBLE", 8}};
    const auto it = types.find(t);
    return it == types.end() ? 0 : it->second;
}

std::optional<ScalarType> meta_image_scalar_type(const std::string& t) {
    static const std::map<std::string, ScalarType> types = {
        {"MET_UCHAR", ScalarType::u8}, {"MET_CHAR", ScalarType::i8}, {"MET_USHORT", ScalarType::u16},
        {"MET_SHORT", ScalarType::i16}, {"MET_UINT", ScalarType::u32}, {"MET_INT", ScalarType::i32},
        {"MET_FLOAT", ScalarType::f32}, {"MET_DOUBLE", ScalarType::f64}};
    const auto it = types.find(t);
    return it == types.end() ? std::nullopt : std::optional<ScalarType>(it->second);
}

std::vector<uint64_t> parse_sizes(const std::string& text, const std::string& what, const std::string& path) {
    std::vector<uint64_t> sizes;
    std::istringstream ss(text);
    std::string tok;
    while (ss >> tok) {
        if (tok.find_first_not_of("0123456789") != std::string::npos || tok.size() > 18)
            throw Error(path, what + " '" + text + "' are not positive integers");
        sizes.push_back(std::stoull(tok));
    }
    if (sizes.empty()) throw Error(path, what + " field is empty");
    return sizes;
}

uint64_t checked_product(const std::vector<uint64_t>& sizes, uint64_t element_bytes, const std::string& path) {
    uint64_t p = element_bytes;
    for (uint64_t s : sizes) {
        if (s == 0) throw Error(path, "header declares an axis of size 0");
        if (p > UINT64_MAX / s) throw Error(path, "header declares more voxels than 64 bits can count");
        p *= s;
    }
    return p;
}

std::optional<std::string> single_data_file(const std::string& header_path, const std::string& name) {
    if (name.empty() || name.find('%') != std::string::npos || name.rfind("LIST", 0) == 0 ||
        name.find(' ') != std::string::npos)
        return std::nullopt;
    if (name[0] == '/') return name;
    const size_t slash = header_path.find_last_of('/');
    return (slash == std::string::npos ? std::string() : header_path.substr(0, slash + 1)) + name;
}

}  // namespace octiso::io
