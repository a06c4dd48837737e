#include "baker/compare/false_color.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace hemibake {

namespace {

// Moreland's cool-warm map at t = 0, 1/8, …, 1 (sRGB bytes).
constexpr std::array<std::array<int, 3>, 9> kCoolWarm = {{{59, 76, 192},
                                                          {98, 130, 234},
                                                          {141, 176, 254},
                                                          {184, 208, 249},
                                                          {221, 221, 221},
                                                          {245, 196, 173},
                                                          {244, 154, 123},
                                                          {222, 96, 77},
                                                          {180, 4, 38}}};

// A tiny pixel font for the scale-bar labels: five rows, `width` columns, bit (width − 1) is the leftmost.
struct Glyph {
    char c;
    int width;
    std::array<std::uint8_t, 5> rows;
};
constexpr std::array<Glyph, 14> kFont = {{{'0', 3, {7, 5, 5, 5, 7}},
                                          {'1', 3, {2, 6, 2, 2, 7}},
                                          {'2', 3, {7, 1, 7, 4, 7}},
                                          {'3', 3, {7, 1, 7, 1, 7}},
                                          {'4', 3, {5, 5, 7, 1, 1}},
                                          {'5', 3, {7, 4, 7, 1, 7}},
                                          {'6', 3, {7, 4, 7, 5, 7}},
                                          {'7', 3, {7, 1, 1, 1, 1}},
                                          {'8', 3, {7, 5, 7, 5, 7}},
                                          {'9', 3, {7, 5, 7, 1, 7}},
                                          {'+', 3, {0, 2, 7, 2, 0}},
                                          {'-', 3, {0, 0, 7, 0, 0}},
                                          {'.', 1, {0, 0, 0, 0, 1}},
                                          {'%', 5, {0x19, 0x1A, 0x04, 0x0B, 0x13}}}};
constexpr int kGlyphScale = 2;  // font pixels are 2×2 image pixels
constexpr int kBarHeight = 12, kMargin = 6, kLabelHeight = 5 * kGlyphScale;

const Glyph* glyph(char c) {
    for (const Glyph& g : kFont)
        if (g.c == c) return &g;
    return nullptr;
}

class Canvas {
public:
    Canvas(int width, int height) {
        image_ = Rgb8Image(width, height);
    }
    void set(int x, int y, glm::u8vec3 c) {
        if (x < 0 || y < 0 || x >= image_.width || y >= image_.height) return;
        image_.at(x, y) = c;
    }
    static int textWidth(const std::string& text) {
        int width = 0;
        for (char c : text) width += (glyph(c) ? glyph(c)->width + 1 : 4) * kGlyphScale;
        return width - kGlyphScale;
    }
    void text(int x, int y, const std::string& s, glm::u8vec3 colour) {
        for (char c : s) {
            const Glyph* g = glyph(c);
            const int width = g ? g->width : 3;
            if (g)
                for (int row = 0; row < 5; ++row)
                    for (int col = 0; col < width; ++col)
                        if (g->rows[std::size_t(row)] & (1 << (width - 1 - col)))
                            for (int dy = 0; dy < kGlyphScale; ++dy)
                                for (int dx = 0; dx < kGlyphScale; ++dx)
                                    set(x + col * kGlyphScale + dx, y + row * kGlyphScale + dy, colour);
            x += (width + 1) * kGlyphScale;
        }
    }
    Rgb8Image take() { return std::move(image_); }

private:
    Rgb8Image image_;
};

}  // namespace

glm::u8vec3 divergingColor(double value, double range) {
    if (!(range > 0.0)) throw std::invalid_argument("false colour: range must be positive");
    if (std::isnan(value)) return {0, 0, 0};
    const double t = std::clamp(0.5 + 0.5 * value / range, 0.0, 1.0) * 8.0;
    const std::size_t i = std::min(std::size_t(t), std::size_t(7));
    const double f = t - double(i);
    glm::u8vec3 c;
    for (int k = 0; k < 3; ++k)
        c[k] = std::uint8_t(std::lround((1.0 - f) * kCoolWarm[i][std::size_t(k)] + f * kCoolWarm[i + 1][std::size_t(k)]));
    return c;
}

std::string percentLabel(double range) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g%%", 100.0 * range);
    return buf;
}

Rgb8Image falseColorMap(const std::vector<float>& signedError, int width, int height, double range) {
    if (width <= 0 || height <= 0 || signedError.size() != std::size_t(width) * std::size_t(height))
        throw std::invalid_argument("false colour: map size does not match its data");
    const int scale = std::max(1, 256 / std::max(width, height));
    const std::string low = "-" + percentLabel(range), high = "+" + percentLabel(range);
    const int mapWidth = width * scale, mapHeight = height * scale;
    const int minWidth = 4 * kMargin + Canvas::textWidth(low) + Canvas::textWidth("0") + Canvas::textWidth(high);
    const int canvasWidth = std::max(mapWidth, minWidth);
    Canvas canvas(canvasWidth, mapHeight + 3 * kMargin + kBarHeight + kLabelHeight);
    const int mapLeft = (canvasWidth - mapWidth) / 2;
    for (int y = 0; y < mapHeight; ++y)
        for (int x = 0; x < mapWidth; ++x)
            canvas.set(mapLeft + x, y,
                       divergingColor(signedError[std::size_t(y / scale) * std::size_t(width) + std::size_t(x / scale)], range));

    // Scale bar: ramp from −range (left) to +range (right), ticks at both ends and at 0, labels below.
    const int barLeft = kMargin, barRight = canvasWidth - kMargin - 1, barTop = mapHeight + kMargin;
    const glm::u8vec3 white(255, 255, 255);
    for (int x = barLeft; x <= barRight; ++x) {
        const double v = range * (2.0 * (x - barLeft) / double(barRight - barLeft) - 1.0);
        for (int y = 0; y < kBarHeight; ++y) canvas.set(x, barTop + y, divergingColor(v, range));
    }
    const int centre = (barLeft + barRight) / 2;
    for (int y = barTop + kBarHeight; y < barTop + kBarHeight + kMargin / 2; ++y)
        for (int x : {barLeft, centre, barRight}) canvas.set(x, y, white);
    const int labelTop = barTop + kBarHeight + kMargin;
    canvas.text(barLeft, labelTop, low, white);
    canvas.text(centre - canvas.textWidth("0") / 2, labelTop, "0", white);
    canvas.text(barRight + 1 - canvas.textWidth(high), labelTop, high, white);
    return canvas.take();
}

}  // namespace hemibake
