#pragma once
// False-colour maps of a signed relative error, for people to look at (the numbers are in the EXR beside it).
//
// Colour ramp: Moreland's cool-to-warm diverging map ("Diverging Color Maps for Scientific Visualization",
// 2009), as 9 of its sRGB control points linearly interpolated: −range is blue (59, 76, 192), 0 is light grey
// (221, 221, 221), +range is red (180, 4, 38). Values beyond ±range clamp to the end colours. Pixels without
// data (NaN: no texel there) are black; infinite values (a reference of 0 against a non-zero value) show as the
// end colour of their sign.
//
// Scale bar: below the map, a strip with the ramp from −range to +range and the labels "−R%", "0", "+R%".
// Maps smaller than 256 pixels are enlarged by an integer factor (nearest neighbour) so that they can be seen.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "baker/util/image.h"

namespace hemibake {


// The ramp colour of `value` for a symmetric range ±range (range > 0).
glm::u8vec3 divergingColor(double value, double range);

// The map of `signedError` (width × height, rows top to bottom, NaN = no data) with the scale bar below it.
Rgb8Image falseColorMap(const std::vector<float>& signedError, int width, int height, double range);

// The scale-bar label for a range, e.g. 0.1 → "10%", 0.025 → "2.5%".
std::string percentLabel(double range);

}  // namespace hemibake
