// The tables in docs/accuracy.md: hemicube form-factor error against resolution for the GROUND_TRUTH.md cases,
// printed as Markdown. A report, not a check (tests/raster/hemicube_test.cpp holds the assertions, with tolerances
// this table explains); it was a disabled test before, which every test run listed as not run. Regenerate with
//   build/bench/hemicube_accuracy_table
// Real OSMesa rendering; 10 s on this 2-core machine, the same figures as the docs. Exit 1 with one line if the GL
// context fails.
#include <cstdio>
#include <exception>

#include "raster/hemicube.h"
#include "support/raster_cases.h"

namespace hemibake {
namespace {

using namespace hemibake::test;

constexpr int kResolutions[] = {32, 64, 128, 256};

void printTables() {
    GlContext context;
    std::printf("\n### Point form factors (192 jittered, randomly rotated hemicubes each): RMS / max relative error, mean (bias)\n\n");
    std::printf("| case | exact F | R=32 | R=64 | R=128 | R=256 |\n|---|---|---|---|---|---|\n");
    for (const PointCase& c : pointCases()) {
        const PatchMesh mesh = c.mesh();
        SceneBuffers buffers(context, mesh);
        std::printf("| %s | %.6f |", c.name.c_str(), c.groundTruth);
        for (int r : kResolutions) {
            HemicubeRenderer renderer(buffers, r);
            const ErrorStats s = pointCaseErrors(renderer, c, 192, 2024);
            std::printf(" %.1e / %.1e (%+.0e) |", s.rms, s.max, s.mean);
        }
        std::printf("\n");
        std::fflush(stdout);
    }
    std::printf("\n### Area form factors (16×16 hemicubes over the source, randomly rotated): relative error vs exact; "
                "[vs the same 16×16 quadrature of exact point form factors]\n\n");
    std::printf("| case | exact F | quadrature bias | R=32 | R=64 | R=128 | R=256 |\n|---|---|---|---|---|---|---|\n");
    for (const AreaCase& c : areaCases()) {
        const PatchMesh mesh = areaCaseMesh(c);
        SceneBuffers buffers(context, mesh);
        std::printf("| %s | %.6f |", c.name.c_str(), c.groundTruth);
        bool first = true;
        for (int r : kResolutions) {
            HemicubeRenderer renderer(buffers, r);
            const AreaEstimate e = areaCaseEstimate(renderer, c, 16, 77);
            if (first) std::printf(" %+.1e |", e.quadrature / c.groundTruth - 1.0);
            first = false;
            std::printf(" %+.1e [%+.1e] |", e.hemicube / c.groundTruth - 1.0, e.hemicube / e.quadrature - 1.0);
        }
        std::printf("\n");
        std::fflush(stdout);
    }
}

}  // namespace
}  // namespace hemibake

int main() {
    try {
        hemibake::printTables();
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "hemicube_accuracy_table: %s\n", e.what());
        return 1;
    }
}
