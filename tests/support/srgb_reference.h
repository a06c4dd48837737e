#pragma once
// An independent sRGB encoder (IEC 61966-2-1) for checking the PNGs the baker writes.
#include <algorithm>
#include <cmath>

namespace hemibake::test {

inline int srgb8(double linear) {
    linear = std::clamp(linear, 0.0, 1.0);
    const double c = linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
    return int(std::lround(c * 255.0));
}

}  // namespace hemibake::test
