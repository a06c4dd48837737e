// Lightmap image outputs: the EXR atlases (float round trip, atomic writes) and the 8-bit sRGB PNG preview.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>

#include "baker/output/exr_io.h"
#include "baker/output/png_preview.h"
#include "mesh/errors.h"
#include "support/gltf_fixture.h"
#include "support/srgb_reference.h"

namespace hemibake {
namespace {

namespace fs = std::filesystem;
using test::TempDir;


LightmapImage patternImage(int size) {
    LightmapImage image;
    image.resize(size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            image.irradianceOverPi[image.index(x, y)] = glm::vec3(0.01f * float(x + 1), 0.02f * float(y + 1), 0.5f);
            image.state[image.index(x, y)] = TexelState::Covered;
        }
    return image;
}

std::vector<fs::path> filesIn(const fs::path& dir) {
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename());
    std::sort(out.begin(), out.end());
    return out;
}

TEST(ExrIo, FloatRoundTripIsExactIncludingTinyAndHugeValues) {
    TempDir dir;
    LightmapImage image;
    image.resize(4);
    const std::vector<float> values = {0.0f, 1e-6f, 1e6f, 1.0f, 0.333333343f, 3.0e-38f, 65504.0f, 123456.789f,
                                       2.5e-7f, 7.0f, 1e-3f, 42.0f, 0.1f, 9.99e5f, 5e-5f, 0.5f};
    for (std::size_t t = 0; t < values.size(); ++t) {
        image.irradianceOverPi[t] = glm::vec3(values[t], values[(t + 5) % values.size()], values[(t + 11) % values.size()]);
        image.state[t] = TexelState::Covered;
    }
    image.state[0] = TexelState::Empty;  // values[0] is 0 anyway, but its other channels are not
    image.state[5] = TexelState::Dilated;
    const fs::path path = dir.path() / "lightmaps" / "0.exr";
    writeLightmapExr(path, image);
    ASSERT_TRUE(fs::exists(path));

    // Written as float (not half): check the file itself says so.
    auto in = OIIO::ImageInput::open(path.string());
    ASSERT_TRUE(in);
    EXPECT_EQ(in->format_name(), std::string("openexr"));
    EXPECT_EQ(in->spec().format, OIIO::TypeDesc::FLOAT);
    EXPECT_EQ(in->spec().nchannels, 3);
    in->close();

    const LightmapImage back = readLightmapExr(path);
    ASSERT_EQ(back.size, 4);
    EXPECT_EQ(back.irradianceOverPi[0], glm::vec3(0.0f)) << "an Empty texel must be written as 0";
    for (std::size_t t = 1; t < values.size(); ++t)
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(back.irradianceOverPi[t][c], image.irradianceOverPi[t][c]) << "texel " << t << " channel " << c;
    EXPECT_EQ(back.state[0], TexelState::Empty);
    EXPECT_EQ(back.state[2], TexelState::Covered);
}

TEST(ExrIo, RowsAreTopDownAsGltfUvsAddressThem) {
    TempDir dir;
    LightmapImage image;
    image.resize(8);
    image.irradianceOverPi[image.index(6, 1)] = glm::vec3(1.0f, 2.0f, 3.0f);  // x = 6, y = 1 (near the top)
    image.state[image.index(6, 1)] = TexelState::Covered;
    const fs::path path = dir.path() / "a.exr";
    writeLightmapExr(path, image);
    auto in = OIIO::ImageInput::open(path.string());
    ASSERT_TRUE(in);
    std::vector<float> pixels(8 * 8 * 3);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, pixels.data()));
    // OpenImageIO's scanline 1 is the second row from the top.
    EXPECT_EQ(pixels[(1 * 8 + 6) * 3 + 0], 1.0f);
    EXPECT_EQ(pixels[(1 * 8 + 6) * 3 + 2], 3.0f);
    EXPECT_EQ(pixels[(6 * 8 + 1) * 3 + 0], 0.0f);
}

TEST(ExrIo, WritingCreatesMissingFoldersAndLeavesNoTempFiles) {
    TempDir dir;
    const fs::path path = dir.path() / "does" / "not" / "exist" / "lightmaps" / "3.exr";
    writeLightmapExr(path, patternImage(16));
    EXPECT_TRUE(fs::is_regular_file(path));
    EXPECT_EQ(filesIn(path.parent_path()), std::vector<fs::path>{"3.exr"});
    EXPECT_EQ(readLightmapExr(path).irradianceOverPi[readLightmapExr(path).index(3, 2)], glm::vec3(0.04f, 0.06f, 0.5f));
}

TEST(ExrIo, AFailedWriteLeavesTheDestinationUntouchedAndNoPartialFile) {
    TempDir dir;
    // The image is encoded completely, then moving it into place fails (a folder holds the name).
    const fs::path blocked = dir.path() / "0.exr";
    fs::create_directory(blocked);
    fs::create_directory(blocked / "keep");
    EXPECT_ANY_THROW(writeLightmapExr(blocked, patternImage(16)));
    EXPECT_TRUE(fs::is_directory(blocked / "keep"));
    EXPECT_EQ(filesIn(dir.path()), std::vector<fs::path>{"0.exr"}) << "a temp file was left behind";

    // A good file is replaced whole or not at all.
    const fs::path good = dir.path() / "1.exr";
    writeLightmapExr(good, patternImage(16));
    const auto before = fs::file_size(good);
    LightmapImage broken;
    broken.size = 16;  // no texel data
    EXPECT_THROW(writeLightmapExr(good, broken), std::invalid_argument);
    EXPECT_EQ(fs::file_size(good), before);
    EXPECT_EQ(readLightmapExr(good).size, 16);
}

TEST(ExrIo, ReadingBadFilesIsAnInputError) {
    TempDir dir;
    EXPECT_THROW(readLightmapExr(dir.path() / "missing.exr"), InputError);
    const fs::path junk = dir.path() / "junk.exr";
    std::ofstream(junk) << "not an image";
    EXPECT_THROW(readLightmapExr(junk), InputError);
    // Not square.
    const fs::path wide = dir.path() / "wide.exr";
    {
        auto out = OIIO::ImageOutput::create(wide.string());
        ASSERT_TRUE(out);
        OIIO::ImageSpec spec(4, 2, 3, OIIO::TypeDesc::FLOAT);
        ASSERT_TRUE(out->open(wide.string(), spec));
        std::vector<float> px(4 * 2 * 3, 1.0f);
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, px.data()));
        out->close();
    }
    EXPECT_THROW(readLightmapExr(wide), InputError);
}

TEST(PngPreview, PercentileIsNearestRankOverNonEmptyTexels) {
    std::vector<glm::vec3> texels;
    for (int i = 1; i <= 10000; ++i) texels.push_back(glm::vec3(0.0f, float(i), 0.5f));
    std::reverse(texels.begin(), texels.end());
    EXPECT_EQ(brightnessPercentile(texels, {}, 0.999), 9990.0f);
    EXPECT_EQ(brightnessPercentile(texels, {}, 1.0), 10000.0f);
    std::vector<std::uint8_t> mask(texels.size(), 0);
    mask[0] = mask[1] = 1;  // 10000 and 9999
    EXPECT_EQ(brightnessPercentile(texels, mask, 0.999), 10000.0f);
    EXPECT_EQ(brightnessPercentile({}, {}, 0.999), 0.0f);

    LightmapImage image;
    image.resize(4);
    image.irradianceOverPi[3] = glm::vec3(1e9f);  // an Empty texel does not count
    image.state[5] = TexelState::Covered;
    image.irradianceOverPi[5] = glm::vec3(0.25f, 2.0f, 0.5f);
    EXPECT_EQ(lightmapExposureScale(image), 2.0f);
    LightmapImage black;
    black.resize(4);
    EXPECT_EQ(lightmapExposureScale(black), 1.0f);
}

TEST(PngPreview, SrgbEncodingMatchesTheStandard) {
    for (double v : {0.0, 0.001, 0.0031308, 0.01, 0.18, 0.5, 0.99, 1.0, 2.0})
        EXPECT_EQ(int(linearToSrgb8(float(v))), test::srgb8(v)) << v;
    EXPECT_EQ(linearToSrgb8(std::nanf("")), 0);
    EXPECT_EQ(linearToSrgb8(-1.0f), 0);
    for (int i = 0; i < 256; ++i) EXPECT_EQ(linearToSrgb8(srgb8ToLinear(std::uint8_t(i))), i);
}

TEST(PngPreview, WritesAn8BitSrgbPngExposedToThe999thPercentile) {
    TempDir dir;
    LightmapImage image = patternImage(40);
    image.irradianceOverPi[image.index(0, 0)] = glm::vec3(1000.0f);  // one outlier: clipped, not the exposure
    image.state[image.index(39, 39)] = TexelState::Empty;
    const fs::path path = dir.path() / "previews" / "0.png";
    const float k = writeLightmapPreviewPng(path, image);
    // 1600 texels, 1599 non-Empty: nearest rank ceil(0.999 × 1599) = 1598 of 1599 → the second brightest.
    std::vector<float> bright;
    for (std::size_t t = 0; t < image.irradianceOverPi.size(); ++t)
        if (image.state[t] != TexelState::Empty)
            bright.push_back(std::max({image.irradianceOverPi[t].x, image.irradianceOverPi[t].y, image.irradianceOverPi[t].z}));
    std::sort(bright.begin(), bright.end());
    EXPECT_EQ(k, bright[1597]);
    EXPECT_LT(k, 1000.0f);

    auto in = OIIO::ImageInput::open(path.string());
    ASSERT_TRUE(in);
    EXPECT_EQ(in->format_name(), std::string("png"));
    ASSERT_EQ(in->spec().width, 40);
    ASSERT_EQ(in->spec().nchannels, 3);
    EXPECT_EQ(in->spec().format, OIIO::TypeDesc::UINT8);
    std::vector<std::uint8_t> px(40 * 40 * 3);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()));
    for (auto [x, y] : {std::pair{0, 0}, std::pair{5, 7}, std::pair{30, 2}, std::pair{39, 38}, std::pair{39, 39}})
        for (int c = 0; c < 3; ++c) {
            const std::size_t t = image.index(x, y);
            const int expected = image.state[t] == TexelState::Empty ? 0 : test::srgb8(double(image.irradianceOverPi[t][c]) / double(k));
            EXPECT_EQ(int(px[t * 3 + std::size_t(c)]), expected) << x << "," << y << " channel " << c;
        }
    EXPECT_EQ(filesIn(path.parent_path()), std::vector<fs::path>{"0.png"});
}

TEST(PngPreview, EncodesPngInMemory) {
    const std::vector<std::uint8_t> rgb = {255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30};
    const std::vector<std::uint8_t> png = encodePng(rgb.data(), 2, 2, 3);
    ASSERT_GT(png.size(), 8u);
    EXPECT_EQ(png[0], 0x89);
    EXPECT_EQ(png[1], 'P');
    TempDir dir;
    std::ofstream(dir.file("x.png"), std::ios::binary).write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));
    auto in = OIIO::ImageInput::open(dir.file("x.png"));
    ASSERT_TRUE(in);
    std::vector<std::uint8_t> back(12);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, back.data()));
    EXPECT_EQ(back, rgb);
}

}  // namespace
}  // namespace hemibake
