// compare (baker/compare.h): exact figures for identical inputs and known perturbations, in memory and through
// real bake directories (scene + bake.json + EXR atlases); inside-geometry exclusion; layout mismatches.
// Also the pieces `reference` is built from that need EXR reading to check: the progressive merge, and
// `hemibake reference --texels` writing the bake's layout (test_cli cannot read EXRs: it has no OpenImageIO).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <thread>

#include "baker/compare/compare.h"
#include "baker/compare/false_color.h"
#include "baker/compare/html_report.h"
#include "baker/output/exr_io.h"
#include "baker/pipeline/bake_layout.h"
#include "baker/reference/progressive_reference.h"
#include "mesh/errors.h"
#include "mesh/gltf_loader.h"
#include "support/gltf_fixture.h"

using namespace hemibake;
using hemibake::test::GltfFixture;
using hemibake::test::runHemibake;
using hemibake::test::TempDir;
namespace fs = std::filesystem;

namespace {

// One image of n pixels, all compared, values from f(i).
ComparedImage syntheticImage(int width, int height, const std::function<glm::vec3(std::size_t)>& f) {
    ComparedImage im;
    im.name = "synthetic";
    im.width = width;
    im.height = height;
    const std::size_t n = std::size_t(width) * std::size_t(height);
    for (std::size_t i = 0; i < n; ++i) im.a.push_back(f(i));
    im.b = im.a;
    im.compared.assign(n, 1);
    return im;
}

Comparison single(ComparedImage im) {
    Comparison c;
    c.mode = "images";
    c.images.push_back(std::move(im));
    computeErrors(c);
    return c;
}

glm::vec3 texelValue(std::size_t i) { return glm::vec3(1.0f, 0.5f, 0.25f) * (1.0f + 0.01f * float(i % 97)); }

}  // namespace

TEST(Compare, IdenticalInputsHaveExactlyZeroError) {
    const Comparison c = single(syntheticImage(16, 8, texelValue));
    EXPECT_EQ(c.global.texels, 128u);
    EXPECT_EQ(c.global.meanRelativeError, 0.0);
    EXPECT_EQ(c.global.meanSignedRelativeError, 0.0);
    EXPECT_EQ(c.global.p95RelativeError, 0.0);
    EXPECT_EQ(c.global.maxRelativeError, 0.0);
    EXPECT_EQ(c.global.rmse, 0.0);
    EXPECT_EQ(c.global.relativeMse, 0.0);
    EXPECT_EQ(c.global.meanA, c.global.meanB);
    for (const glm::vec3& e : c.images[0].signedRelativeError) EXPECT_EQ(e, glm::vec3(0.0f));
}

TEST(Compare, ScaledReferenceGivesOneEleventh) {
    // B = 1.1 A: |a − b| / b = 0.1 / 1.1 = 1/11 for every sample (all values are far above the floor).
    ComparedImage im = syntheticImage(16, 8, texelValue);
    for (glm::vec3& b : im.b) b *= 1.1f;
    const ComparedImage kept = im;
    const Comparison c = single(std::move(im));
    EXPECT_NEAR(c.global.meanRelativeError, 1.0 / 11.0, 1e-6);
    EXPECT_NEAR(c.global.meanSignedRelativeError, -1.0 / 11.0, 1e-6);
    EXPECT_NEAR(c.global.p95RelativeError, 1.0 / 11.0, 1e-6);
    EXPECT_NEAR(c.global.maxRelativeError, 1.0 / 11.0, 1e-6);
    // RMSE and relative MSE from their definitions, on the same float values.
    double squared = 0.0, relativeSquared = 0.0;
    for (std::size_t i = 0; i < kept.a.size(); ++i)
        for (int ch = 0; ch < 3; ++ch) {
            const double d = double(kept.a[i][ch]) - double(kept.b[i][ch]);
            squared += d * d;
            relativeSquared += d * d / (double(kept.b[i][ch]) * kept.b[i][ch] + c.floor[ch] * c.floor[ch]);
        }
    EXPECT_NEAR(c.global.rmse, std::sqrt(squared / (3.0 * 128.0)), 1e-12);
    EXPECT_NEAR(c.global.relativeMse, relativeSquared / (3.0 * 128.0), 1e-12);
    EXPECT_NEAR(c.global.relativeMse, 1.0 / 121.0, 1e-4);  // floor² is 1e-4 of b²
    // The roles matter: A = 1.1 B is 10 % off.
    ComparedImage swapped = kept;
    std::swap(swapped.a, swapped.b);
    EXPECT_NEAR(single(std::move(swapped)).global.meanRelativeError, 0.1, 1e-6);
}

TEST(Compare, ReferenceNoiseIsTakenOutOfTheErrorAgainstTruth) {
    // Truth t per channel everywhere; B = t·(1 ± 5 %) alternating, with its standard error 5 % of t; A = t·(1 + δ).
    // Per pair of texels (a − b)² = t²((δ − 0.05)² + (δ + 0.05)²) = 2t²δ² + 2σ², so A against the truth is exactly
    // δ on the scale m = mean b = t (floor 1 % of t: δ / sqrt(1.0001)), while the plain figures carry B's noise.
    const glm::vec3 truth(1.0f, 0.5f, 0.25f);
    const double delta = 0.02, noise = 0.05;
    ComparedImage im = syntheticImage(16, 8, [&](std::size_t) { return truth * float(1.0 + delta); });
    for (std::size_t i = 0; i < im.b.size(); ++i) {
        im.b[i] = truth * float(i % 2 ? 1.0 - noise : 1.0 + noise);
        im.bStandardError.push_back(truth * float(noise));
    }
    const ComparedImage kept = im;
    const Comparison c = single(std::move(im));
    ASSERT_TRUE(c.global.knowsReferenceNoise());
    EXPECT_NEAR(c.global.relativeRmseAgainstTruth, delta / std::sqrt(1.0001), 1e-6);
    EXPECT_NEAR(c.global.referenceNoiseRelativeRms, noise / std::sqrt(1.0001), 1e-6);
    EXPECT_GT(std::sqrt(c.global.relativeMse), 2.0 * delta);  // the plain figure is mostly B's noise
    // A equal to the truth scores 0 against it, however noisy B is.
    ComparedImage exact = kept;
    for (glm::vec3& a : exact.a) a = truth;
    EXPECT_NEAR(single(std::move(exact)).global.relativeRmseAgainstTruth, 0.0, 1e-3);
    // Without B's standard error there is no such figure.
    ComparedImage plain = kept;
    plain.bStandardError.clear();
    const Comparison p = single(std::move(plain));
    EXPECT_FALSE(p.global.knowsReferenceNoise());
    EXPECT_LT(p.global.relativeRmseAgainstTruth, 0.0);
}

TEST(Compare, FloorKeepsBlackReferenceTexelsFinite) {
    // B is 1 everywhere except one black texel where A is 2: floor = 1 % of mean |b|.
    ComparedImage im = syntheticImage(10, 10, [](std::size_t) { return glm::vec3(1.0f); });
    im.b[0] = glm::vec3(0.0f);
    im.a[0] = glm::vec3(2.0f);
    const Comparison c = single(std::move(im));
    const double floor = 0.01 * 99.0 / 100.0;
    EXPECT_NEAR(c.floor.x, floor, 1e-15);
    EXPECT_NEAR(c.global.maxRelativeError, 2.0 / floor, 1e-9);
    EXPECT_NEAR(c.global.meanRelativeError, 2.0 / floor / 100.0 + 99.0 / 100.0 * 0.0, 1e-9);
    EXPECT_EQ(c.global.p95RelativeError, 0.0);  // 99 of 100 texels agree
}

TEST(Compare, PercentileIsNearestRank) {
    // Relative errors 0.01, 0.02, …, 1.00 (B = 1, A = 1 + k/100): the 95th percentile is the 95th value.
    ComparedImage im = syntheticImage(100, 1, [](std::size_t) { return glm::vec3(1.0f); });
    for (std::size_t k = 0; k < 100; ++k) im.a[k] = glm::vec3(1.0f + float(k + 1) / 100.0f);
    const Comparison c = single(std::move(im));
    EXPECT_NEAR(c.global.p95RelativeError, 0.95, 1e-6);
    EXPECT_NEAR(c.global.maxRelativeError, 1.0, 1e-6);
    EXPECT_NEAR(c.global.meanRelativeError, 0.505, 1e-6);
}

TEST(Compare, OnlyComparedTexelsCountAndMapsMarkTheRest) {
    ComparedImage im = syntheticImage(4, 4, texelValue);
    im.compared[5] = 0;
    im.a[5] = glm::vec3(100.0f);  // ignored
    const Comparison c = single(std::move(im));
    EXPECT_EQ(c.global.texels, 15u);
    EXPECT_EQ(c.global.maxRelativeError, 0.0);
    EXPECT_TRUE(std::isnan(worstChannelError(c.images[0])[5]));
    EXPECT_EQ(worstChannelError(c.images[0])[4], 0.0f);
}

TEST(FalseColor, RampEndsScaleBarAndNoData) {
    EXPECT_EQ(divergingColor(-0.1, 0.1), glm::u8vec3(59, 76, 192));
    EXPECT_EQ(divergingColor(-5.0, 0.1), glm::u8vec3(59, 76, 192));  // clamped
    EXPECT_EQ(divergingColor(0.0, 0.1), glm::u8vec3(221, 221, 221));
    EXPECT_EQ(divergingColor(0.1, 0.1), glm::u8vec3(180, 4, 38));
    EXPECT_EQ(divergingColor(std::numeric_limits<double>::infinity(), 0.1), glm::u8vec3(180, 4, 38));
    EXPECT_EQ(divergingColor(std::nan(""), 0.1), glm::u8vec3(0, 0, 0));
    EXPECT_EQ(percentLabel(0.1), "10%");
    EXPECT_EQ(percentLabel(0.025), "2.5%");
    // A 16×16 map is enlarged 16× and gets the scale bar below it.
    std::vector<float> error(256, 0.05f);
    error[0] = std::nanf("");
    const Rgb8Image map = falseColorMap(error, 16, 16, 0.1);
    EXPECT_EQ(map.width, 256);
    EXPECT_GT(map.height, 256 + 20);
    auto pixel = [&](int x, int y) { return map.at(x, y); };
    EXPECT_EQ(pixel(3, 3), glm::u8vec3(0, 0, 0));               // no data
    EXPECT_EQ(pixel(100, 100), divergingColor(0.05, 0.1));      // +5 %
    EXPECT_EQ(pixel(6, 256 + 6 + 2), glm::u8vec3(59, 76, 192));  // the bar starts at −range
}

TEST(HtmlReport, IsSelfContained) {
    ComparedImage im = syntheticImage(8, 8, texelValue);
    for (glm::vec3& b : im.b) b *= 1.1f;
    Comparison c = single(std::move(im));
    c.a = "a<&>.exr";
    const std::string html = htmlReport(c);
    std::size_t images = 0;
    for (std::size_t at = html.find("data:image/png;base64,"); at != std::string::npos;
         at = html.find("data:image/png;base64,", at + 1))
        ++images;
    EXPECT_EQ(images, 3u);  // A, B, error map
    EXPECT_EQ(html.find("src=\"http"), std::string::npos);
    EXPECT_NE(html.find("a&lt;&amp;&gt;.exr"), std::string::npos);
    EXPECT_NE(html.find("9.09%"), std::string::npos);  // the mean relative error, 1/11
    EXPECT_EQ(base64({'M', 'a', 'n'}), "TWFu");
    EXPECT_EQ(base64({'M', 'a'}), "TWE=");
    EXPECT_EQ(base64({'M'}), "TQ==");
}

// ---- Real bake directories ----

namespace {

// floor (2 × 2 m, faces +y), a bottomless 0.5 m box standing on it, and a 1 × 1 m emitter at y = 2 facing down.
std::string writeScene(const TempDir& dir) {
    GltfFixture g;
    const int white = g.addMaterial({{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1.0}}, {"metallicFactor", 0.0}}}});
    const int light = g.addMaterial({{"pbrMetallicRoughness", {{"baseColorFactor", {0.0, 0.0, 0.0, 1.0}}, {"metallicFactor", 0.0}}},
                                     {"emissiveFactor", {1.0, 1.0, 1.0}}});
    const int floorPos = g.addPositions({-1, 0, -1, -1, 0, 1, 1, 0, 1, 1, 0, -1});
    g.addNode({{"name", "floor"}, {"mesh", g.addMesh(floorPos, g.addIndicesU16({0, 1, 2, 0, 2, 3}), white)}});
    // Box corners: x, z in [-0.25, 0.25], y in [0, 0.5]; outward faces, no bottom.
    const float h = 0.25f;
    const int boxPos = g.addPositions({-h, 0, -h, h, 0, -h, h, 0, h, -h, 0, h, -h, 0.5f, -h, h, 0.5f, -h, h, 0.5f, h, -h, 0.5f, h});
    const int boxIdx = g.addIndicesU16({4, 7, 6, 4, 6, 5,    // top, +y
                                        0, 4, 5, 0, 5, 1,    // z = -h, -z
                                        2, 6, 7, 2, 7, 3,    // z = +h, +z
                                        3, 7, 4, 3, 4, 0,    // x = -h, -x
                                        1, 5, 6, 1, 6, 2});  // x = +h, +x
    g.addNode({{"name", "block"}, {"mesh", g.addMesh(boxPos, boxIdx, white)}});
    const int lightPos = g.addPositions({-0.5f, 2, -0.5f, 0.5f, 2, -0.5f, 0.5f, 2, 0.5f, -0.5f, 2, 0.5f});
    g.addNode({{"name", "light"}, {"mesh", g.addMesh(lightPos, g.addIndicesU16({0, 1, 2, 0, 2, 3}), light)}});
    return g.writeGltf(dir, "room");
}

struct FakeBake {
    fs::path dir;
    std::vector<LightmapImage> atlases;
    BakeLayout layout;
};

// A bake directory as `hemibake bake` writes it (bake.json with lightmap + primitives, EXR atlases), with
// texel values from `value(atlas, texel index, instance)`; the layout is rebuilt the way compare rebuilds it.
FakeBake writeBake(const fs::path& dir, const std::string& scenePath,
                   const std::function<glm::vec3(std::size_t, std::size_t, int)>& value) {
    const double texelsPerUnit = 16.0;
    const Scene scene = loadGltf(scenePath);
    LightmapSettings lightmap;
    lightmap.texelsPerUnit = texelsPerUnit;
    const UvAtlas atlas = unwrapScene(scene, unwrapSettingsFor(lightmap));
    const std::vector<AtlasTexels> texels = computeTexels(scene, atlas);
    nlohmann::json files = nlohmann::json::array(), primitives = nlohmann::json::array();
    FakeBake bake;
    bake.dir = dir;
    for (std::size_t a = 0; a < texels.size(); ++a) {
        const std::string rel = "lightmaps/" + std::to_string(a) + ".exr";
        files.push_back(rel);
        LightmapImage image;
        image.resize(texels[a].size);
        for (std::size_t i = 0; i < texels[a].count(); ++i) {
            const std::size_t p = image.index(texels[a].x[i], texels[a].y[i]);
            image.irradianceOverPi[p] = value(a, i, texels[a].instance[i]);
            image.state[p] = TexelState::Covered;
        }
        writeLightmapExr(dir / rel, image);
        bake.atlases.push_back(image);
    }
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const UnwrappedInstance& u = atlas.instances[i];
        primitives.push_back({{"node", scene.instances[i].source.nodeName},
                              {"mesh", scene.instances[i].source.mesh},
                              {"primitive", 0},
                              {"lightmap", files[std::size_t(u.atlas)]},
                              {"rect", {u.rect[0], u.rect[1], u.rect[2], u.rect[3]}}});
    }
    const nlohmann::json report = {{"format", "hemibake-bake/1"},
                                   {"scene", scenePath},
                                   {"settings", {{"skyRadiance", {0.0, 0.0, 0.0}}, {"texelsPerUnit", texelsPerUnit}}},
                                   {"lightmap", {{"texelsPerUnit", texelsPerUnit}, {"files", files}}},
                                   {"primitives", primitives}};
    std::ofstream(dir / "bake.json") << report.dump(2);
    bake.layout = loadBakeLayout(dir);
    return bake;
}

glm::vec3 smooth(std::size_t, std::size_t i, int) { return glm::vec3(0.8f, 0.6f, 0.4f) * (1.0f + 0.002f * float(i % 50)); }

}  // namespace

TEST(CompareBakes, OffsetOnOnePrimitiveShowsThereOnly) {
    TempDir dir;
    const std::string scene = writeScene(dir);
    const FakeBake a = writeBake(dir.path() / "a", scene, smooth);
    const int block = 1;  // instance of node "block"
    const glm::vec3 offset(0.2f);
    const FakeBake b = writeBake(dir.path() / "b", scene, [&](std::size_t at, std::size_t i, int instance) {
        return smooth(at, i, instance) + (instance == block ? offset : glm::vec3(0.0f));
    });

    const Comparison same = compareLightmapDirectories(a.dir, a.dir);
    EXPECT_EQ(same.global.meanRelativeError, 0.0);
    EXPECT_EQ(same.global.maxRelativeError, 0.0);

    const Comparison c = compareLightmapDirectories(a.dir, b.dir);
    EXPECT_TRUE(c.warnings.empty()) << c.warnings.front();
    ASSERT_EQ(c.primitives.size(), 3u);
    EXPECT_EQ(c.primitives[0].entry["node"], "floor");
    EXPECT_EQ(c.primitives[0].stats.meanRelativeError, 0.0);
    EXPECT_EQ(c.primitives[2].stats.meanRelativeError, 0.0);
    // The expected figure on the block, and its share of the global one, from the texels themselves.
    double sum = 0.0, max = 0.0;
    std::size_t blockTexels = 0, allTexels = 0, inside = 0;
    for (std::size_t at = 0; at < a.layout.texels.size(); ++at) {
        const AtlasTexels& t = a.layout.texels[at];
        inside += c.images[at].insideTexels;
        allTexels += t.count();
        for (std::size_t i = 0; i < t.count(); ++i) {
            if (t.instance[i] != block) continue;
            ++blockTexels;
            const glm::vec3 av = smooth(at, i, block), bv = av + offset;
            for (int ch = 0; ch < 3; ++ch) {
                const double r = std::abs(double(av[ch]) - double(bv[ch])) / double(bv[ch]);
                sum += r;
                max = std::max(max, r);
            }
        }
    }
    ASSERT_GT(blockTexels, 50u);
    EXPECT_EQ(c.primitives[block].stats.texels, blockTexels);
    EXPECT_NEAR(c.primitives[block].stats.meanRelativeError, sum / (3.0 * double(blockTexels)), 1e-9);
    EXPECT_NEAR(c.primitives[block].stats.maxRelativeError, max, 1e-9);
    EXPECT_NEAR(c.primitives[block].stats.meanSignedRelativeError, -sum / (3.0 * double(blockTexels)), 1e-9);
    EXPECT_EQ(c.global.texels, allTexels - inside);
    EXPECT_NEAR(c.global.meanRelativeError, sum / (3.0 * double(allTexels - inside)), 1e-9);

    // Floor texels under the block (a 0.5 × 0.5 m footprint of the 2 × 2 m floor) are inside geometry.
    const double floorTexels = double(c.primitives[0].stats.texels + inside);
    EXPECT_GT(double(inside), 0.04 * floorTexels);
    EXPECT_LT(double(inside), 0.10 * floorTexels);
    const Comparison all = compareLightmapDirectories(a.dir, b.dir, true);
    EXPECT_EQ(all.global.texels, allTexels);

    const nlohmann::json j = c.toJson();
    EXPECT_EQ(j["format"], "hemibake-compare/1");
    EXPECT_EQ(j["primitives"][1]["node"], "block");
    EXPECT_DOUBLE_EQ(j["primitives"][1]["errors"]["meanRelativeError"].get<double>(), c.primitives[1].stats.meanRelativeError);
}

TEST(CompareBakes, MismatchedLayoutsAreInputErrors) {
    TempDir dir;
    const std::string scene = writeScene(dir);
    const FakeBake a = writeBake(dir.path() / "a", scene, smooth);
    writeBake(dir.path() / "b", scene, smooth);
    // A smaller atlas in B.
    LightmapImage small;
    small.resize(8);
    writeLightmapExr(dir.path() / "b/lightmaps/0.exr", small);
    try {
        compareLightmapDirectories(a.dir, dir.path() / "b");
        FAIL() << "sizes differ";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("b/lightmaps/0.exr"), std::string::npos) << e.what();
    }
    // A primitive elsewhere in C.
    writeBake(dir.path() / "c", scene, smooth);
    nlohmann::json report = nlohmann::json::parse(std::ifstream(dir.path() / "c/bake.json"));
    report["primitives"][1]["rect"][0] = report["primitives"][1]["rect"][0].get<int>() + 1;
    std::ofstream(dir.path() / "c/bake.json") << report.dump();
    try {
        compareLightmapDirectories(a.dir, dir.path() / "c");
        FAIL() << "primitives differ";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("c/bake.json"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("block"), std::string::npos) << e.what();
    }
    EXPECT_THROW(compareInputs(a.dir, a.dir / "lightmaps/0.exr"), InputError);  // a directory and a file
    EXPECT_THROW(compareInputs(a.dir, dir.path() / "missing"), InputError);
}

// ---- reference --texels: the bake's layout, read back from the EXRs ----

TEST(ReferenceTexels, WritesTheBakeLayoutAndComparesAsABake) {
    TempDir dir;
    const std::string scene = writeScene(dir);
    const FakeBake bake = writeBake(dir.path() / "bake", scene, smooth);
    const fs::path ref = dir.path() / "ref";
    const auto r = runHemibake({"reference", "--texels", bake.dir.string(), "-o", ref.string(), "--spp", "8", "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["format"], "hemibake-reference/1");
    EXPECT_EQ(j["spp"], 8);
    EXPECT_EQ(j["primitives"], nlohmann::json::parse(std::ifstream(bake.dir / "bake.json"))["primitives"]);
    EXPECT_NE(r.err.find("8 spp"), std::string::npos) << r.err;

    for (std::size_t a = 0; a < bake.atlases.size(); ++a) {
        const LightmapImage values = readLightmapExr(ref / ("lightmaps/" + std::to_string(a) + ".exr"));
        const LightmapImage errors = readLightmapExr(ref / ("lightmaps/" + std::to_string(a) + ".stderr.exr"));
        ASSERT_EQ(values.size, bake.atlases[a].size);
        ASSERT_EQ(errors.size, bake.atlases[a].size);
        std::size_t lit = 0, texels = 0;
        for (std::size_t p = 0; p < values.irradianceOverPi.size(); ++p) {
            if (bake.atlases[a].state[p] == TexelState::Empty) {
                EXPECT_EQ(values.irradianceOverPi[p], glm::vec3(0.0f)) << "texel " << p << " has no bake texel";
                EXPECT_EQ(errors.irradianceOverPi[p], glm::vec3(0.0f));
            } else {
                ++texels;
                lit += values.irradianceOverPi[p].x > 0.0f;
            }
        }
        EXPECT_GT(lit, texels * 8 / 10);  // all but the texels under the block and the light's own back
    }
    // REF/ is a bake for compare: the layout comes from reference.json's source.
    const Comparison c = compareLightmapDirectories(bake.dir, ref);
    EXPECT_TRUE(c.warnings.empty()) << c.warnings.front();
    EXPECT_GT(c.global.texels, 100u);
    EXPECT_GT(c.global.meanRelativeError, 0.0);
    const Comparison back = compareLightmapDirectories(ref, bake.dir);
    EXPECT_EQ(back.global.texels, c.global.texels);
    // REF carries its standard error, so the bake gets a noise-corrected figure; the bake (no .stderr.exr) as B
    // gives the path tracer none.
    EXPECT_TRUE(c.global.knowsReferenceNoise());
    EXPECT_GT(c.global.referenceNoiseRelativeRms, 0.0);
    EXPECT_FALSE(back.global.knowsReferenceNoise());
    EXPECT_FALSE(c.toJson()["global"]["relativeRmseAgainstTruth"].is_null());
    EXPECT_TRUE(back.toJson()["global"]["relativeRmseAgainstTruth"].is_null());
}

// ---- Progressive passes ----

TEST(ProgressiveReference, PassesDoubleAndMergeExactly) {
    // Pass k gives every point the mean k + 1 and standard error 0.5 with `spp` samples.
    std::vector<std::uint32_t> passSpp;
    std::vector<std::uint64_t> seeds;
    const ProgressiveEstimate e = estimateProgressively(
        3, {20, 0.0}, 7, [&](std::uint64_t seed, std::uint32_t spp, std::vector<Estimate>& out) {
            passSpp.push_back(spp);
            seeds.push_back(seed);
            for (Estimate& x : out) {
                x.mean = glm::dvec3(double(passSpp.size()));
                x.standardError = glm::dvec3(0.5);
                x.rays = spp;
            }
        });
    EXPECT_EQ(passSpp, (std::vector<std::uint32_t>{2, 2, 4, 8, 4}));
    EXPECT_EQ(seeds[0], 7u);
    for (std::size_t k = 1; k < seeds.size(); ++k) EXPECT_NE(seeds[k], seeds[k - 1]);
    EXPECT_EQ(e.status.spp, 20u);
    EXPECT_EQ(e.status.passes, 5u);
    EXPECT_EQ(e.status.rays, 3u * 20u);
    EXPECT_FALSE(e.status.timeLimited);
    // Merged mean and pooled variance, written out: Σ n_k m_k / N and (Σ (n_k − 1) s_k² + Σ n_k (m_k − m)²) / (N − 1).
    double mean = 0.0, m2 = 0.0;
    for (std::size_t k = 0; k < passSpp.size(); ++k) mean += passSpp[k] * double(k + 1) / 20.0;
    for (std::size_t k = 0; k < passSpp.size(); ++k) {
        const double n = passSpp[k];
        m2 += 0.25 * n * (n - 1.0) + n * (double(k + 1) - mean) * (double(k + 1) - mean);
    }
    EXPECT_NEAR(e.mean[2].y, mean, 1e-12);
    EXPECT_NEAR(e.standardError[2].y, std::sqrt(m2 / 19.0 / 20.0), 1e-12);
}

TEST(ProgressiveReference, TimeLimitStopsEarlyButKeepsTheFirstPass) {
    const ProgressiveEstimate e = estimateProgressively(
        1, {1u << 20, 0.2}, 1, [](std::uint64_t, std::uint32_t spp, std::vector<Estimate>& out) {
            std::this_thread::sleep_for(std::chrono::microseconds(2000) * spp);  // 2 ms per sample
            out[0].mean = glm::dvec3(1.0);
        });
    EXPECT_TRUE(e.status.timeLimited);
    EXPECT_GE(e.status.spp, 2u);
    EXPECT_LT(e.status.spp, 200u);
    // Every sample sleeps 2 ms, and it stops only when one more would not fit the 0.2 s (no wall-clock ceiling).
    EXPECT_GE(e.status.seconds, 0.002 * e.status.spp);
    EXPECT_GE(e.status.seconds * (1.0 + 1.0 / e.status.spp), 0.2);
}
