#pragma once
// Exact solid angle of cube-map texels, so projections onto SH integrate the sphere without the
// corner-vs-centre bias of the usual 4/(R²·(1+s²+t²)^{3/2}) approximation.
//
// On the face plane at distance 1, the solid angle of the rectangle [0, s] × [0, t] is
// A(s, t) = atan2(s·t, √(s² + t² + 1)); a texel [s0, s1] × [t0, t1] is the inclusion–exclusion of its four
// corners. All 6R² texels sum to 4π (up to rounding).
#include <vector>

namespace hemibake {

double cubeTexelSolidAngle(double s0, double t0, double s1, double t1);

// R×R solid angles of one face (every face is the same), row-major from the lower-left texel: texel (i, j) at
// index j·R + i, covering s ∈ [−1 + 2i/R, −1 + 2(i+1)/R] and t likewise with j.
std::vector<double> cubeFaceSolidAngles(int resolution);

}  // namespace hemibake
