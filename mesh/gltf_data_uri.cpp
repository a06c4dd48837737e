#include "mesh/gltf_data_uri.h"

#include <cstdio>

namespace hemibake {

namespace {

bool isBase64Char(char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '+' || c == '/';
}

std::string describeChar(char c) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f && c != '\'') return std::string("'") + c + "'";
    char buf[8];
    std::snprintf(buf, sizeof buf, "0x%02X", unsigned(u));
    return buf;
}

}  // namespace

std::string dataUriProblem(std::string_view uri, std::size_t* decodedBytes) {
    if (decodedBytes) *decodedBytes = 0;
    if (uri.substr(0, 5) != "data:") return "is not a data URI";
    const std::size_t comma = uri.find(',');
    if (comma == std::string_view::npos) return "data URI has no ',' before its data";
    const std::string_view header = uri.substr(5, comma - 5);
    constexpr std::string_view kBase64 = ";base64";
    if (header.size() < kBase64.size() || header.substr(header.size() - kBase64.size()) != kBase64)
        return "data URI is not base64-encoded (only \"data:...;base64,\" URIs are read)";
    const std::string_view payload = uri.substr(comma + 1);
    if (payload.empty()) return "data URI holds no data";
    std::size_t symbols = 0;  // base64 characters before any padding
    while (symbols < payload.size() && isBase64Char(payload[symbols])) ++symbols;
    std::size_t padding = 0;
    while (symbols + padding < payload.size() && payload[symbols + padding] == '=') ++padding;
    const std::size_t bad = symbols + padding;
    if (bad < payload.size())
        return "data URI is not valid base64: " + describeChar(payload[bad]) + " at position " + std::to_string(bad) +
               " of its " + std::to_string(payload.size()) + " data characters";
    // Padding (optional) completes the last group of 4; a lone character in a group encodes no whole byte.
    if (symbols % 4 == 1 || padding > 2 || (padding > 0 && (symbols + padding) % 4 != 0))
        return "data URI is not valid base64: " + std::to_string(payload.size()) +
               " data characters do not form whole groups of 4";
    if (decodedBytes) *decodedBytes = symbols / 4 * 3 + (symbols % 4 == 0 ? 0 : symbols % 4 - 1);
    return "";
}

std::string elideDataUris(const std::string& text) {
    std::string out;
    std::size_t at = 0;
    while (true) {
        const std::size_t start = text.find("data:", at);
        if (start == std::string::npos) break;
        const std::size_t comma = text.find(',', start);
        if (comma == std::string::npos) break;
        std::size_t end = comma + 1;
        while (end < text.size() && text[end] != ' ' && text[end] != '\n' && text[end] != '"' && text[end] != '\'') ++end;
        out.append(text, at, comma + 1 - at);
        out += "…(" + std::to_string(end - comma - 1) + " characters)";
        at = end;
    }
    out.append(text, at, std::string::npos);
    return out;
}

}  // namespace hemibake
