#include "baker/compare/html_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "baker/compare/false_color.h"
#include "baker/output/png_preview.h"
#include "baker/util/atomic_output.h"

namespace hemibake {

namespace {

std::string escapeHtml(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string number(double v, const char* format = "%.4g") {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

std::string percent(double fraction) { return number(100.0 * fraction, "%.3g") + "%"; }

std::string triple(const glm::dvec3& v) { return number(v.x) + " " + number(v.y) + " " + number(v.z); }

std::string pngDataUri(const Rgb8Image& image) {
    return "data:image/png;base64," +
           base64(encodePng(reinterpret_cast<const std::uint8_t*>(image.pixels.data()), image.width, image.height, 3));
}

// sRGB(value / exposure) of every pixel.
Rgb8Image exposed(const std::vector<glm::vec3>& pixels, int width, int height, float exposure) {
    Rgb8Image image(width, height);
    for (std::size_t p = 0; p < pixels.size(); ++p)
        for (int c = 0; c < 3; ++c) image.pixels[p][c] = linearToSrgb8(pixels[p][c] / exposure);
    return image;
}

void statsHeader(std::ostringstream& o, const std::string& first) {
    o << "<tr><th>" << first << "</th><th>texels</th><th>mean rel. error</th><th>mean signed rel.</th><th>p95 rel.</th>"
      << "<th>max rel.</th><th>RMSE</th><th>rel. MSE</th><th>mean A (R G B)</th><th>mean B (R G B)</th></tr>\n";
}

void statsRow(std::ostringstream& o, const std::string& first, const ErrorStats& s) {
    o << "<tr><td>" << first << "</td><td>" << s.texels << "</td><td>" << percent(s.meanRelativeError) << "</td><td>"
      << percent(s.meanSignedRelativeError) << "</td><td>" << percent(s.p95RelativeError) << "</td><td>"
      << percent(s.maxRelativeError) << "</td><td>" << number(s.rmse) << "</td><td>" << number(s.relativeMse) << "</td><td>"
      << triple(s.meanA) << "</td><td>" << triple(s.meanB) << "</td></tr>\n";
}

}  // namespace

std::string base64(const std::vector<std::uint8_t>& bytes) {
    static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const std::uint32_t n = std::uint32_t(bytes[i]) << 16 | (i + 1 < bytes.size() ? std::uint32_t(bytes[i + 1]) << 8 : 0u) |
                                (i + 2 < bytes.size() ? std::uint32_t(bytes[i + 2]) : 0u);
        out += kAlphabet[(n >> 18) & 63];
        out += kAlphabet[(n >> 12) & 63];
        out += i + 1 < bytes.size() ? kAlphabet[(n >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? kAlphabet[n & 63] : '=';
    }
    return out;
}

std::string htmlReport(const Comparison& c, const HtmlReportOptions& options) {
    std::ostringstream o;
    o << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>hemibake compare: "
      << escapeHtml(c.a) << " vs " << escapeHtml(c.b) << "</title>\n<style>\n"
      << "body{font-family:sans-serif;margin:1.5em;background:#fafafa;color:#222}"
      << "table{border-collapse:collapse;margin:.5em 0 1.5em}td,th{border:1px solid #ccc;padding:.2em .5em;"
      << "text-align:right;font-variant-numeric:tabular-nums}td:first-child,th:first-child{text-align:left}"
      << ".row{display:flex;gap:1em;flex-wrap:wrap;align-items:flex-start}figure{margin:0}"
      << "img{image-rendering:pixelated;border:1px solid #888;background:#000}"
      << "figcaption{font-size:.9em;margin-top:.3em}code{background:#eee;padding:0 .2em}\n</style></head><body>\n";
    o << "<h1>hemibake compare</h1>\n<p>A: <code>" << escapeHtml(c.a) << "</code><br>B (reference): <code>"
      << escapeHtml(c.b) << "</code><br>Mode: " << escapeHtml(c.mode) << "</p>\n";
    for (const std::string& w : c.warnings) o << "<p><b>Warning:</b> " << escapeHtml(w) << "</p>\n";

    o << "<h2>Global</h2>\n<table>\n";
    statsHeader(o, "");
    statsRow(o, "all", c.global);
    o << "</table>\n";

    for (const ComparedImage& im : c.images) {
        // One exposure for A and B: the 99.9th percentile brightness of B's compared texels.
        std::vector<glm::vec3> reference;
        for (std::size_t p = 0; p < im.b.size(); ++p)
            if (im.compared[p]) reference.push_back(im.b[p]);
        float exposure = brightnessPercentile(reference, {}, 0.999);
        if (!(exposure > 0.0f) || !std::isfinite(exposure)) exposure = 1.0f;
        const Rgb8Image map = falseColorMap(worstChannelError(im), im.width, im.height, options.mapRange);
        const int displayWidth = std::max(256, std::min(im.width, 512));
        o << "<h2>" << escapeHtml(im.name) << " (" << im.width << "×" << im.height << ")</h2>\n<div class=\"row\">\n";
        o << "<figure><img width=\"" << displayWidth << "\" src=\"" << pngDataUri(exposed(im.a, im.width, im.height, exposure))
          << "\" alt=\"A\"><figcaption>A</figcaption></figure>\n";
        o << "<figure><img width=\"" << displayWidth << "\" src=\"" << pngDataUri(exposed(im.b, im.width, im.height, exposure))
          << "\" alt=\"B\"><figcaption>B (reference); both shown as sRGB(value / " << number(exposure) << ")</figcaption></figure>\n";
        // falseColorMap enlarges small maps and may add margins for the scale bar: keep its map at displayWidth.
        const int mapScale = std::max(1, 256 / std::max(im.width, im.height));
        o << "<figure><img width=\"" << displayWidth * map.width / (im.width * mapScale) << "\" src=\"" << pngDataUri(map)
          << "\" alt=\"error map\"><figcaption>signed relative error (a−b)/max(|b|, floor), worst channel, ±"
          << percent(options.mapRange) << "; black: no texel</figcaption></figure>\n</div>\n<table>\n";
        statsHeader(o, "");
        statsRow(o, escapeHtml(im.name), im.stats);
        o << "</table>\n";
    }

    if (!c.primitives.empty()) {
        o << "<h2>Per primitive</h2>\n<table>\n";
        statsHeader(o, "node / mesh / primitive (lightmap, rect)");
        for (const PrimitiveComparison& p : c.primitives)
            statsRow(o,
                     escapeHtml(p.entry.value("node", "")) + " / " + std::to_string(p.entry.value("mesh", -1)) + " / " +
                         std::to_string(p.entry.value("primitive", -1)) + " (" + escapeHtml(p.entry.value("lightmap", "")) +
                         " " + escapeHtml(p.entry.value("rect", nlohmann::json()).dump()) + ")",
                     p.stats);
        o << "</table>\n";
    }
    o << "<h2>Definitions</h2>\n<p>Every texel contributes its three channels as samples; B is the reference. "
      << "Relative error r = |a−b| / max(|b|, floor), floor = " << kFloorFractionOfMean
      << " × mean |b| per channel over all compared texels (" << triple(c.floor) << "). "
      << "Mean signed relative error: mean of (a−b)/max(|b|, floor). p95: nearest-rank 95th percentile of r. "
      << "RMSE = sqrt(mean (a−b)²) in the values' units. Relative MSE = mean (a−b)² / (b² + floor²). "
      << "Error map colours: Moreland's cool-to-warm diverging ramp, blue at −" << percent(options.mapRange)
      << ", grey at 0, red at +" << percent(options.mapRange) << ", clamped beyond.</p>\n</body></html>\n";
    return o.str();
}

void writeHtmlReport(const std::filesystem::path& path, const Comparison& comparison, const HtmlReportOptions& options) {
    writeTextAtomically(path, htmlReport(comparison, options));
}

}  // namespace hemibake
