// `hemibake compare A B`: error figures of A against the reference B (baker/compare.h has the definitions),
// globally, per atlas and per primitive; false-colour error maps (--map) and a self-contained HTML page (--html).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "baker/compare/compare.h"
#include "baker/compare/false_color.h"
#include "baker/compare/html_report.h"
#include "baker/output/png_preview.h"
#include "baker/util/rgb_image.h"
#include "cli/command.h"

namespace hemibake::cli {

namespace {

namespace fs = std::filesystem;

struct CompareOptions {
    std::string a, b;
    bool json = false;
    std::string html;
    std::string mapPrefix;
    double mapRange = 0.1;
    bool includeInside = false;
};

std::string row(const std::string& label, const ErrorStats& s) {
    char buf[512];
    std::snprintf(buf, sizeof buf, "%-40s %9llu %9.4f%% %9.4f%% %9.4f%% %9.4f%% %11.5g %11.5g  %.5g %.5g %.5g  %.5g %.5g %.5g",
                  label.c_str(), static_cast<unsigned long long>(s.texels), 100.0 * s.meanRelativeError,
                  100.0 * s.meanSignedRelativeError, 100.0 * s.p95RelativeError, 100.0 * s.maxRelativeError, s.rmse,
                  s.relativeMse, s.meanA.x, s.meanA.y, s.meanA.z, s.meanB.x, s.meanB.y, s.meanB.z);
    return buf;
}

void printText(const Comparison& c) {
    char header[512];
    std::snprintf(header, sizeof header, "%-40s %9s %10s %10s %10s %10s %11s %11s  %s", "(B is the reference)", "texels",
                  "mean rel", "mean sgn", "p95 rel", "max rel", "RMSE", "rel MSE", "mean A (RGB)  mean B (RGB)");
    std::cout << header << "\n" << row("global", c.global) << "\n";
    if (c.global.knowsReferenceNoise()) {
        char noise[256];
        std::snprintf(noise, sizeof noise,
                      "B carries its standard error: A against the noise-free answer %.4f%% RMS, B's own noise %.4f%% "
                      "(relative to each primitive's mean)\n",
                      100.0 * c.global.relativeRmseAgainstTruth, 100.0 * c.global.referenceNoiseRelativeRms);
        std::cout << noise;
    }
    for (const ComparedImage& im : c.images) std::cout << row(im.name, im.stats) << "\n";
    for (const PrimitiveComparison& p : c.primitives)
        std::cout << row(p.entry.value("node", "") + "/" + std::to_string(p.entry.value("mesh", -1)) + "/" +
                             std::to_string(p.entry.value("primitive", -1)),
                         p.stats)
                  << "\n";
}

// PREFIX.exr / PREFIX.png for two images; PREFIX-<atlas>.exr / .png per atlas for two bakes.
nlohmann::json writeMaps(const Comparison& c, const std::string& prefix, double range) {
    nlohmann::json written = nlohmann::json::array();
    for (const ComparedImage& im : c.images) {
        const std::string base = c.mode == "images" ? prefix : prefix + "-" + fs::path(im.name).stem().string();
        RgbImage error(im.width, im.height);
        for (std::size_t p = 0; p < error.pixels.size(); ++p)
            error.pixels[p] = std::isnan(im.signedRelativeError[p].x) ? glm::vec3(0.0f) : im.signedRelativeError[p];
        writeRgbExr(base + ".exr", error);
        const Rgb8Image map = falseColorMap(worstChannelError(im), im.width, im.height, range);
        writeBytesAtomically(base + ".png", encodePng(reinterpret_cast<const std::uint8_t*>(map.pixels.data()), map.width, map.height, 3));
        written.push_back({{"image", im.name}, {"exr", base + ".exr"}, {"png", base + ".png"}});
    }
    return written;
}

int runCompare(const CompareOptions& o) {
    const Comparison c = compareInputs(o.a, o.b, o.includeInside);
    for (const std::string& w : c.warnings) std::cerr << "hemibake: warning: " << w << "\n";
    nlohmann::json j = c.toJson();
    if (!o.mapPrefix.empty()) j["maps"] = writeMaps(c, o.mapPrefix, o.mapRange);
    j["mapRange"] = o.mapRange;
    if (!o.html.empty()) {
        writeHtmlReport(o.html, c, {o.mapRange});
        j["html"] = o.html;
    }
    if (o.json)
        std::cout << j.dump(2) << "\n";
    else
        printText(c);
    return 0;
}

}  // namespace

CommandRunner addCompareCommand(CLI::App& app) {
    auto o = std::make_shared<CompareOptions>();
    CLI::App* cmd = app.add_subcommand(
        "compare",
        "Error of A against the reference B: two bake/reference directories texel for texel (covered texels of the "
        "bake's layout; per atlas and per primitive), or two images of equal size. Relative error "
        "|a-b|/max(|b|, floor), floor = 1% of B's mean per channel; also p95/max relative error, RMSE, relative MSE. When B is a "
        "`reference --texels` output it carries its standard error (.stderr.exr), and A's RMS error against the "
        "noise-free answer is reported too (B's own noise taken out; relative to each primitive's mean)");
    cmd->add_option("a", o->a, "Result: a bake directory, a `reference --texels` directory, or an image (EXR)")->required();
    cmd->add_option("b", o->b, "Reference: the same kind as A")->required();
    cmd->add_flag("--json", o->json, "Print the figures as one JSON object (hemibake-compare/1)");
    cmd->add_option("--html", o->html, "Write a self-contained HTML page: A, B and the error map side by side, and the tables");
    cmd->add_option("--map", o->mapPrefix,
                    "Write error maps: PREFIX-<atlas>.exr (signed relative error per channel, 0 where no texel) and "
                    "PREFIX-<atlas>.png (false colour with scale bar); PREFIX.exr/.png for two images");
    cmd->add_option("--map-range", o->mapRange,
                    "Signed relative error at the ends of the colour ramp (blue -R, grey 0, red +R)")
        ->capture_default_str()->check(CLI::PositiveNumber);
    cmd->add_flag("--include-inside", o->includeInside,
                  "Also compare texels inside or under geometry (by default left out: more than 10% of their "
                  "hemisphere sees back faces, the bake's criterion; they are never visible)");
    return [o]() { return runCompare(*o); };
}

}  // namespace hemibake::cli
