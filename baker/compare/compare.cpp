#include "baker/compare/compare.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include "baker/output/exr_io.h"
#include "baker/pipeline/bake_layout.h"
#include "baker/rays/embree_scene.h"
#include "baker/rays/inside_geometry.h"
#include "baker/util/rgb_image.h"
#include "mesh/errors.h"

namespace hemibake {

namespace fs = std::filesystem;

namespace {

nlohmann::json vec(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

// Sums and the relative-error samples of one group of texels (global, an atlas, a primitive).
class ErrorAccumulator {
public:
    // `bError`: B's standard error at this texel, or null when B is exact; `meanB`: B's mean over the texel's
    // primitive (the noise-free scale of relativeRmseAgainstTruth).
    void add(const glm::vec3& a, const glm::vec3& b, const glm::dvec3& floor, const glm::vec3* bError,
             const glm::dvec3& meanB) {
        ++texels_;
        if (!bError) exactReference_ = true;
        for (int c = 0; c < 3; ++c) {
            const double diff = double(a[c]) - double(b[c]);
            const double scale = std::max(std::abs(double(b[c])), floor[c]);
            const double relative = std::abs(diff) / scale;
            relative_.push_back(relative);
            sumRelative_ += relative;
            sumSigned_ += diff / scale;
            sumSquared_ += diff * diff;
            const double scaleSquared = double(b[c]) * double(b[c]) + floor[c] * floor[c];
            sumRelativeSquared_ += diff * diff / scaleSquared;
            if (bError) {
                const double meanScaleSquared = meanB[c] * meanB[c] + floor[c] * floor[c];
                const double noise = double((*bError)[c]) * double((*bError)[c]);
                sumAgainstTruth_ += (diff * diff - noise) / meanScaleSquared;
                sumNoise_ += noise / meanScaleSquared;
            }
            sumA_[c] += a[c];
            sumB_[c] += b[c];
        }
    }

    ErrorStats finish() {
        ErrorStats s;
        s.texels = texels_;
        if (texels_ == 0) return s;
        const double n = double(relative_.size());
        s.meanRelativeError = sumRelative_ / n;
        s.meanSignedRelativeError = sumSigned_ / n;
        s.rmse = std::sqrt(sumSquared_ / n);
        s.relativeMse = sumRelativeSquared_ / n;
        if (!exactReference_) {
            s.relativeRmseAgainstTruth = std::sqrt(std::max(sumAgainstTruth_ / n, 0.0));
            s.referenceNoiseRelativeRms = std::sqrt(sumNoise_ / n);
        }
        s.meanA = sumA_ / double(texels_);
        s.meanB = sumB_ / double(texels_);
        const std::size_t rank = std::size_t(std::ceil(kPercentile * n)) - 1;
        std::nth_element(relative_.begin(), relative_.begin() + std::ptrdiff_t(rank), relative_.end());
        s.p95RelativeError = relative_[rank];
        s.maxRelativeError = *std::max_element(relative_.begin(), relative_.end());
        return s;
    }

private:
    std::uint64_t texels_ = 0;
    std::vector<double> relative_;
    double sumRelative_ = 0.0, sumSigned_ = 0.0, sumSquared_ = 0.0, sumRelativeSquared_ = 0.0;
    double sumAgainstTruth_ = 0.0, sumNoise_ = 0.0;
    bool exactReference_ = false;  // some texel had no standard error: the noise figure would be partial
    glm::dvec3 sumA_{0.0}, sumB_{0.0};
};

void checkSizes(const ComparedImage& im) {
    const std::size_t n = std::size_t(im.width) * std::size_t(im.height);
    if (im.width <= 0 || im.height <= 0 || im.a.size() != n || im.b.size() != n || im.compared.size() != n ||
        (!im.primitive.empty() && im.primitive.size() != n) || (!im.bStandardError.empty() && im.bStandardError.size() != n))
        throw std::invalid_argument("compare: " + im.name + ": arrays do not match the image size");
}

glm::dvec3 relativeErrorFloor(const std::vector<ComparedImage>& images) {
    glm::dvec3 sum(0.0);
    std::uint64_t count = 0;
    for (const ComparedImage& im : images)
        for (std::size_t p = 0; p < im.b.size(); ++p)
            if (im.compared[p]) {
                sum += glm::abs(glm::dvec3(im.b[p]));
                ++count;
            }
    const glm::dvec3 mean = count ? sum / double(count) : glm::dvec3(0.0);
    const double overall = (mean.x + mean.y + mean.z) / 3.0;
    glm::dvec3 floor;
    for (int c = 0; c < 3; ++c)
        floor[c] = std::max(kFloorFractionOfMean * (mean[c] > 0.0 ? mean[c] : overall),
                            double(std::numeric_limits<float>::min()));
    return floor;
}

}  // namespace

nlohmann::json toJson(const ErrorStats& s) {
    nlohmann::json j = {{"texels", s.texels},
            {"meanRelativeError", s.meanRelativeError},
            {"meanSignedRelativeError", s.meanSignedRelativeError},
            {"p95RelativeError", s.p95RelativeError},
            {"maxRelativeError", s.maxRelativeError},
            {"rmse", s.rmse},
            {"relativeMse", s.relativeMse},
            {"meanA", vec(s.meanA)},
            {"meanB", vec(s.meanB)}};
    if (s.knowsReferenceNoise()) {
        j["relativeRmseAgainstTruth"] = s.relativeRmseAgainstTruth;
        j["referenceNoiseRelativeRms"] = s.referenceNoiseRelativeRms;
    }
    return j;
}

void computeErrors(Comparison& c) {
    for (const ComparedImage& im : c.images) checkSizes(im);
    c.floor = relativeErrorFloor(c.images);
    // B's mean per primitive (index = primitive + 1; 0 collects texels of none, per image below).
    std::vector<glm::dvec3> primitiveSum(c.primitives.size() + 1, glm::dvec3(0.0));
    std::vector<double> primitiveCount(c.primitives.size() + 1, 0.0);
    const auto slot = [&](const ComparedImage& im, std::size_t p) {
        const std::int32_t prim = im.primitive.empty() ? -1 : im.primitive[p];
        return prim >= 0 && std::size_t(prim) < c.primitives.size() ? std::size_t(prim) + 1 : std::size_t(0);
    };
    for (const ComparedImage& im : c.images)
        for (std::size_t p = 0; p < im.b.size(); ++p)
            if (im.compared[p] && slot(im, p) > 0) {
                primitiveSum[slot(im, p)] += glm::dvec3(im.b[p]);
                primitiveCount[slot(im, p)] += 1.0;
            }
    ErrorAccumulator global;
    std::vector<ErrorAccumulator> perPrimitive(c.primitives.size());
    for (ComparedImage& im : c.images) {
        ErrorAccumulator atlas;
        glm::dvec3 noPrimitiveSum(0.0);
        double noPrimitiveCount = 0.0;
        for (std::size_t p = 0; p < im.b.size(); ++p)
            if (im.compared[p] && slot(im, p) == 0) {
                noPrimitiveSum += glm::dvec3(im.b[p]);
                noPrimitiveCount += 1.0;
            }
        primitiveSum[0] = noPrimitiveSum;
        primitiveCount[0] = noPrimitiveCount;
        im.signedRelativeError.assign(im.a.size(), glm::vec3(std::numeric_limits<float>::quiet_NaN()));
        for (std::size_t p = 0; p < im.a.size(); ++p) {
            if (!im.compared[p]) continue;
            const glm::vec3 a = im.a[p], b = im.b[p];
            const glm::vec3* bError = im.bStandardError.empty() ? nullptr : &im.bStandardError[p];
            const std::size_t k = slot(im, p);
            const glm::dvec3 meanB = primitiveSum[k] / std::max(primitiveCount[k], 1.0);
            global.add(a, b, c.floor, bError, meanB);
            atlas.add(a, b, c.floor, bError, meanB);
            if (k > 0) perPrimitive[k - 1].add(a, b, c.floor, bError, meanB);
            for (int ch = 0; ch < 3; ++ch)
                im.signedRelativeError[p][ch] =
                    float((double(a[ch]) - double(b[ch])) / std::max(std::abs(double(b[ch])), c.floor[ch]));
        }
        im.stats = atlas.finish();
    }
    c.global = global.finish();
    for (std::size_t k = 0; k < c.primitives.size(); ++k) c.primitives[k].stats = perPrimitive[k].finish();
}

std::vector<float> worstChannelError(const ComparedImage& image) {
    std::vector<float> worst(image.signedRelativeError.size(), std::numeric_limits<float>::quiet_NaN());
    for (std::size_t p = 0; p < worst.size(); ++p) {
        const glm::vec3 e = image.signedRelativeError[p];
        if (std::isnan(e.x)) continue;
        float w = e.x;
        for (int c = 1; c < 3; ++c)
            if (std::abs(e[c]) > std::abs(w)) w = e[c];
        worst[p] = w;
    }
    return worst;
}

nlohmann::json Comparison::toJson() const {
    nlohmann::json j;
    j["format"] = "hemibake-compare/1";
    j["mode"] = mode;
    j["a"] = a;
    j["b"] = b;
    j["reference"] = "b";
    j["definitions"] = {{"relativeError", "|a-b| / max(|b|, floor), per channel sample"},
                        {"floor", "floorFractionOfMean x mean |b| per channel over the compared texels"},
                        {"floorFractionOfMean", kFloorFractionOfMean},
                        {"percentile", "nearest rank"},
                        {"relativeMse", "mean (a-b)^2 / (b^2 + floor^2)"},
                        {"relativeRmseAgainstTruth", "sqrt(max(0, mean ((a-b)^2 - stderr_b^2) / (m^2 + floor^2))), m = mean b over the texel's primitive; when b carries its standard error"},
                        {"referenceNoiseRelativeRms", "sqrt(mean stderr_b^2 / (m^2 + floor^2))"}};
    j["floor"] = vec(floor);
    j["global"] = hemibake::toJson(global);
    j["images"] = nlohmann::json::array();
    for (const ComparedImage& im : images) {
        nlohmann::json e = hemibake::toJson(im.stats);
        e["name"] = im.name;
        e["width"] = im.width;
        e["height"] = im.height;
        e["insideGeometryTexels"] = im.insideTexels;
        j["images"].push_back(e);
    }
    j["primitives"] = nlohmann::json::array();
    for (const PrimitiveComparison& p : primitives) {
        nlohmann::json e = p.entry;
        e["errors"] = hemibake::toJson(p.stats);
        j["primitives"].push_back(e);
    }
    j["warnings"] = warnings;
    return j;
}

Comparison compareImageFiles(const fs::path& a, const fs::path& b) {
    const RgbImage imageA = readRgbImage(a), imageB = readRgbImage(b);
    if (imageA.width != imageB.width || imageA.height != imageB.height)
        throw InputError(b.string(), "is " + std::to_string(imageB.width) + "x" + std::to_string(imageB.height) + " pixels but " +
                                         a.string() + " is " + std::to_string(imageA.width) + "x" +
                                         std::to_string(imageA.height) + ": images must be the same size");
    Comparison c;
    c.mode = "images";
    c.a = a.string();
    c.b = b.string();
    ComparedImage im;
    im.name = a.filename().string();
    im.width = imageA.width;
    im.height = imageA.height;
    im.a = imageA.pixels;
    im.b = imageB.pixels;
    im.compared.assign(im.a.size(), 1);
    c.images.push_back(std::move(im));
    computeErrors(c);
    return c;
}

// ---- Lightmap directories ----

namespace {

// What a bake (bake.json) or a texel reference (reference.json) directory says about its lightmaps.
struct LightmapSet {
    fs::path dir;
    fs::path reportPath;
    nlohmann::json report;
    std::vector<std::string> files;  // atlas EXRs relative to dir
    nlohmann::json primitives;       // bake.json primitives list
    std::optional<fs::path> layoutDir;  // a directory with the bake.json whose layout these lightmaps follow
};

LightmapSet readLightmapSet(const fs::path& dir) {
    LightmapSet s;
    s.dir = dir;
    const bool isBake = fs::exists(dir / "bake.json");
    s.reportPath = dir / (isBake ? "bake.json" : "reference.json");
    std::ifstream in(s.reportPath);
    if (!in) throw InputError(dir.string(), "has neither bake.json nor reference.json (not a bake or reference directory)");
    try {
        s.report = nlohmann::json::parse(in);
    } catch (const std::exception& e) {
        throw InputError(s.reportPath.string(), std::string("is not valid JSON: ") + e.what());
    }
    const std::string format = s.report.value("format", "");
    if (format != (isBake ? "hemibake-bake/1" : "hemibake-reference/1"))
        throw InputError(s.reportPath.string(), "format is \"" + format + "\", expected " +
                                                    (isBake ? "hemibake-bake/1" : "hemibake-reference/1"));
    s.primitives = s.report.value("primitives", nlohmann::json::array());
    for (std::size_t k = 0; k < s.primitives.size(); ++k) {
        const nlohmann::json& p = s.primitives[k];
        bool ok = p.is_object() && p.value("lightmap", nlohmann::json()).is_string() && p.contains("rect") &&
                  p["rect"].is_array() && p["rect"].size() == 4;
        for (std::size_t i = 0; ok && i < 4; ++i) ok = p["rect"][i].is_number_integer();
        if (!ok)
            throw InputError(s.reportPath.string(), "primitives[" + std::to_string(k) + "] needs \"lightmap\" (a path) and "
                                                    "\"rect\" (4 integers)");
    }
    const nlohmann::json lightmap = s.report.value("lightmap", nlohmann::json::object());
    for (const auto& f : lightmap.value("files", nlohmann::json::array())) {
        if (!f.is_string()) throw InputError(s.reportPath.string(), "lightmap.files must list paths");
        s.files.push_back(f.get<std::string>());
    }
    if (s.files.empty())
        for (const auto& p : s.primitives) {
            const std::string f = p.value("lightmap", "");
            if (!f.empty() && std::find(s.files.begin(), s.files.end(), f) == s.files.end()) s.files.push_back(f);
        }
    if (s.files.empty()) throw InputError(s.reportPath.string(), "lists no lightmaps (the bake wrote none)");
    if (isBake)
        s.layoutDir = dir;
    else if (const nlohmann::json source = s.report.value("source", nlohmann::json());
             source.is_string() && fs::exists(fs::path(source.get<std::string>()) / "bake.json"))
        s.layoutDir = fs::path(source.get<std::string>());
    return s;
}

std::string describePrimitive(const nlohmann::json& p) {
    return "primitive (node \"" + p.value("node", "") + "\", mesh " + std::to_string(p.value("mesh", -1)) + ", primitive " +
           std::to_string(p.value("primitive", -1)) + ")";
}

void checkSameLayout(const LightmapSet& a, const LightmapSet& b) {
    if (a.files != b.files)
        throw InputError(b.reportPath.string(), "lists lightmaps " + nlohmann::json(b.files).dump() + " but " +
                                                    a.reportPath.string() + " lists " + nlohmann::json(a.files).dump() +
                                                    ": not the same layout");
    if (a.primitives.size() != b.primitives.size())
        throw InputError(b.reportPath.string(), "lists " + std::to_string(b.primitives.size()) + " primitives but " +
                                                    a.reportPath.string() + " lists " + std::to_string(a.primitives.size()));
    for (std::size_t k = 0; k < a.primitives.size(); ++k) {
        const auto& pa = a.primitives[k];
        const auto& pb = b.primitives[k];
        if (pa.value("lightmap", "") != pb.value("lightmap", "") || pa.value("rect", nlohmann::json()) != pb.value("rect", nlohmann::json()))
            throw InputError(b.reportPath.string(), describePrimitive(pb) + " is at " + pb.value("lightmap", "") + " " +
                                                        pb.value("rect", nlohmann::json()).dump() + " but in " +
                                                        a.reportPath.string() + " at " + pa.value("lightmap", "") + " " +
                                                        pa.value("rect", nlohmann::json()).dump() + ": not the same layout");
    }
}

bool rectEquals(const nlohmann::json& rect, const std::array<std::int32_t, 4>& r) {
    if (!rect.is_array() || rect.size() != 4) return false;
    for (std::size_t k = 0; k < 4; ++k)
        if (rect[k].get<std::int64_t>() != r[k]) return false;
    return true;
}

bool insideRect(const nlohmann::json& rect, int x, int y) {
    if (!rect.is_array() || rect.size() != 4) return false;
    const int rx = rect[0].get<int>(), ry = rect[1].get<int>(), rw = rect[2].get<int>(), rh = rect[3].get<int>();
    return x >= rx && y >= ry && x < rx + rw && y < ry + rh;
}

// Per Scene instance, the index of the bake.json primitive it is (−1 when none): same lightmap file and the same
// rectangle; among equal candidates, in order.
std::vector<std::int32_t> primitiveOfInstance(const BakeLayout& layout, const nlohmann::json& primitives) {
    std::vector<std::int32_t> of(layout.atlas.instances.size(), -1);
    for (std::size_t k = 0; k < primitives.size(); ++k) {
        const std::string file = primitives[k].value("lightmap", "");
        for (std::size_t i = 0; i < layout.atlas.instances.size(); ++i) {
            const UnwrappedInstance& inst = layout.atlas.instances[i];
            if (of[i] >= 0 || inst.atlas < 0 || std::size_t(inst.atlas) >= layout.lightmapFiles.size()) continue;
            if (layout.lightmapFiles[std::size_t(inst.atlas)] == file && rectEquals(primitives[k]["rect"], inst.rect)) {
                of[i] = std::int32_t(k);
                break;
            }
        }
    }
    return of;
}

// The eligible primitive whose rectangle holds (x, y) in atlas `file`, first in list order; −1 when none.
std::int32_t primitiveByRect(const nlohmann::json& primitives, const std::vector<bool>& eligible, const std::string& file,
                             int x, int y) {
    for (std::size_t k = 0; k < primitives.size(); ++k)
        if (eligible[k] && primitives[k].value("lightmap", "") == file && insideRect(primitives[k]["rect"], x, y))
            return std::int32_t(k);
    return -1;
}

}  // namespace

Comparison compareLightmapDirectories(const fs::path& a, const fs::path& b, bool includeInsideGeometry) {
    const LightmapSet setA = readLightmapSet(a), setB = readLightmapSet(b);
    checkSameLayout(setA, setB);
    Comparison c;
    c.mode = "lightmaps";
    c.a = a.string();
    c.b = b.string();
    for (const auto& p : setA.primitives) c.primitives.push_back({p, {}});

    // The layout: which texels are covered, and by which instance.
    std::optional<BakeLayout> layout;
    for (const LightmapSet* s : {&setA, &setB}) {
        if (layout || !s->layoutDir) continue;
        try {
            layout = loadBakeLayout(*s->layoutDir);
        } catch (const std::exception& e) {
            c.warnings.push_back(std::string("cannot rebuild the bake layout: ") + e.what());
        }
    }
    if (layout && layout->lightmapFiles != setA.files) {
        c.warnings.push_back("the layout of " + layout->outDir.string() + " lists other lightmap files; not using it");
        layout.reset();
    }
    if (!layout) c.warnings.push_back("comparing the texels that are non-zero in A or B, primitives by rectangle");
    std::unique_ptr<EmbreeScene> rays;
    if (layout && !includeInsideGeometry) rays = std::make_unique<EmbreeScene>(layout->scene);
    const std::vector<std::int32_t> instancePrimitive =
        layout ? primitiveOfInstance(*layout, setA.primitives) : std::vector<std::int32_t>{};
    // Primitives found by rectangle: all without a layout, else those that match no instance of it.
    std::vector<bool> byRect(setA.primitives.size(), true);
    if (layout)
        for (std::size_t k = 0; k < setA.primitives.size(); ++k) {
            byRect[k] = std::find(instancePrimitive.begin(), instancePrimitive.end(), std::int32_t(k)) == instancePrimitive.end();
            if (byRect[k])
                c.warnings.push_back(describePrimitive(setA.primitives[k]) + " matches no instance of the layout; its "
                                     "figures use the unclaimed texels in its rectangle");
        }

    // A path-traced B carries its standard error beside every atlas; one missing and the noise figures are left out.
    const auto errorFile = [&](const std::string& file) { return standardErrorPath(b / file); };
    std::error_code ec;
    const bool referenceErrors = std::all_of(setA.files.begin(), setA.files.end(),
                                             [&](const std::string& file) { return fs::exists(errorFile(file), ec); });

    for (std::size_t atlas = 0; atlas < setA.files.size(); ++atlas) {
        const std::string& file = setA.files[atlas];
        const LightmapImage la = readLightmapExr(a / file), lb = readLightmapExr(b / file);
        if (la.size != lb.size)
            throw InputError((b / file).string(), "is " + std::to_string(lb.size) + "x" + std::to_string(lb.size) + " texels but " +
                                                      (a / file).string() + " is " + std::to_string(la.size) + "x" +
                                                      std::to_string(la.size) + ": not the same layout");
        if (layout && layout->texels[atlas].size != la.size)
            throw InputError((a / file).string(), "is " + std::to_string(la.size) + " texels wide but the bake's layout has " +
                                                      std::to_string(layout->texels[atlas].size) + ": not the same layout");
        ComparedImage im;
        im.name = file;
        im.width = im.height = la.size;
        im.a = la.irradianceOverPi;
        im.b = lb.irradianceOverPi;
        if (referenceErrors) {
            LightmapImage errors = readLightmapExr(errorFile(file));
            if (errors.size != lb.size)
                throw InputError(errorFile(file).string(), "is " + std::to_string(errors.size) + " texels wide but " +
                                                               (b / file).string() + " is " + std::to_string(lb.size));
            im.bStandardError = std::move(errors.irradianceOverPi);
        }
        im.compared.assign(im.a.size(), 0);
        im.primitive.assign(im.a.size(), -1);
        if (layout) {
            const AtlasTexels& t = layout->texels[atlas];
            const std::vector<std::uint8_t> inside =
                rays ? texelsInsideGeometry(layout->scene, *rays, t) : std::vector<std::uint8_t>(t.count(), 0);
            for (std::size_t i = 0; i < t.count(); ++i) {
                if (inside[i]) {
                    ++im.insideTexels;
                    continue;
                }
                const std::size_t p = la.index(t.x[i], t.y[i]);
                im.compared[p] = 1;
                const std::int32_t inst = t.instance[i];
                im.primitive[p] = inst >= 0 && std::size_t(inst) < instancePrimitive.size() ? instancePrimitive[std::size_t(inst)] : -1;
            }
            for (std::size_t p = 0; p < im.a.size(); ++p)
                if (im.compared[p] && im.primitive[p] < 0)
                    im.primitive[p] = primitiveByRect(setA.primitives, byRect, file, int(p % std::size_t(la.size)),
                                                      int(p / std::size_t(la.size)));
        } else {
            for (std::size_t p = 0; p < im.a.size(); ++p) {
                if (la.state[p] == TexelState::Empty && lb.state[p] == TexelState::Empty) continue;
                im.compared[p] = 1;
                im.primitive[p] = primitiveByRect(setA.primitives, byRect, file, int(p % std::size_t(la.size)),
                                                  int(p / std::size_t(la.size)));
            }
        }
        c.images.push_back(std::move(im));
    }
    computeErrors(c);
    return c;
}

Comparison compareInputs(const fs::path& a, const fs::path& b, bool includeInsideGeometry) {
    std::error_code ec;
    for (const fs::path& p : {a, b})
        if (!fs::exists(p, ec)) throw InputError(p.string(), "not found");
    const bool dirA = fs::is_directory(a, ec), dirB = fs::is_directory(b, ec);
    if (dirA != dirB)
        throw InputError(b.string(), std::string("is a ") + (dirB ? "directory" : "file") + " but " + a.string() + " is a " +
                                         (dirA ? "directory" : "file") +
                                         ": compare two bake/reference directories or two images");
    return dirA ? compareLightmapDirectories(a, b, includeInsideGeometry) : compareImageFiles(a, b);
}

}  // namespace hemibake
