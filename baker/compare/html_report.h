#pragma once
// `compare --html`: one self-contained page (no external files: images are embedded as base64 PNG data URIs)
// with, per atlas or image, A, the reference B and the false-colour error map side by side, and the tables of
// figures (global, per atlas, per primitive) with their definitions.
//
// A and B are shown with one exposure, the 99.9th percentile of max(R, G, B) over B's compared texels (as the
// PNG previews do, baker/png_preview.h), so brightness differences between them are visible.
#include <filesystem>
#include <string>

#include "baker/compare/compare.h"

namespace hemibake {

struct HtmlReportOptions {
    double mapRange = 0.1;  // ± signed relative error at the ends of the colour ramp
};

std::string htmlReport(const Comparison& comparison, const HtmlReportOptions& options = {});
// Writes the page atomically. Throws std::runtime_error naming the file.
void writeHtmlReport(const std::filesystem::path& path, const Comparison& comparison, const HtmlReportOptions& options = {});

// Standard base64 (RFC 4648, with padding).
std::string base64(const std::vector<std::uint8_t>& bytes);

}  // namespace hemibake
