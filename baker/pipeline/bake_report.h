#pragma once
// bake.json ("hemibake-bake/1", CONVENTIONS.md): settings, timings per stage, peak memory, convergence history,
// the power ledger, one entry per baked primitive, and a section per later stage. Written only here.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "baker/lightmap/lightmap_baker.h"
#include "baker/lightmap/lightmap_seams.h"
#include "baker/lightmap/surface_agreement.h"
#include "baker/output/gltf_writer.h"
#include "baker/pipeline/bake_settings.h"
#include "baker/solve/direct_steps.h"
#include "baker/solve/exposed_area.h"
#include "baker/solve/room_scale.h"
#include "baker/solve/radiosity_solver.h"
#include "baker/solve/separate_sides.h"
#include "raster/hemicube.h"

namespace hemibake {

struct StageTiming {
    std::string stage;
    double seconds = 0.0;  // wall time; stages do not overlap
};

struct RefinementReport {
    std::size_t elementsBefore = 0, elementsAfter = 0, regions = 0;  // adaptive refinement
    RoomScaleReport roomScale;                                        // before it: elements that follow the rooms
    DirectStepReport directSteps;                                     // and where direct light steps
};

// Triangles the hemicubes drew (summed over their five faces), against the triangles a hemicube could draw: how
// much the culling leaves llvmpipe to do.
struct HemicubeDrawReport {
    std::size_t sceneTriangles = 0;  // element triangles uploaded (each hemicube face could draw them all)
    HemicubeDrawTotals solve;        // the final solve's shots and gather sweeps
    HemicubeDrawTotals finalGather;  // the lightmap texels' gathers
};

struct LightmapReport {
    double texelsPerUnit = 0.0;             // density actually used
    std::vector<std::string> files;         // per atlas, relative to OUT
    struct Atlas { int size = 0; double utilization = 0.0; };
    std::vector<Atlas> atlases;
    std::size_t charts = 0;
    LightmapStats stats;
    std::vector<SurfaceAgreement> surfaces;
    SeamStats seams;
};

struct ProbesReport {
    std::string file;
    std::size_t count = 0, insideGeometry = 0;
    double seconds = 0.0;
};

struct VolumeReport {
    std::vector<std::string> files;
    glm::ivec3 resolution{0};
    glm::dvec3 min{0.0}, max{0.0};
    std::size_t probes = 0, invalid = 0, relocated = 0;
    std::uintmax_t bytes = 0;
    double seconds = 0.0;
};

struct PreviewReport {
    std::string camera, exr, png;
    int width = 0, height = 0;
};

struct BakeReport {
    std::string scenePath, sceneAbsolute;
    BakeSettings settings;                  // as resolved (preset, overrides, texel density)
    std::vector<StageTiming> timings;
    double totalSeconds = 0.0;              // wall time of the whole bake
    double peakMemoryMiB = 0.0;
    bool hugePageHeap = false;              // glibc backs the whole heap with transparent huge pages (heapInHugePages)
    std::size_t patches = 0, elements = 0, triangles = 0;
    std::size_t islands = 0;  // groups of parts far apart, each with lengths of its own size (mesh/islands.h)
    std::vector<std::string> warnings;
    SolveReport solve;
    SolidCutStats solidCuts;  // faces cut along solids before subdivision (mesh/solid_cuts.h)
    ExposedAreaReport exposedArea;
    SideSeparationReport sides;
    RefinementReport refinement;
    HemicubeDrawReport hemicubeDraws;
    std::optional<LightmapReport> lightmap;
    std::vector<BakedPrimitive> primitives;
    std::optional<ProbesReport> probes;
    std::optional<VolumeReport> volume;
    std::optional<PreviewReport> preview;

    nlohmann::json toJson() const;
};

// Peak resident memory of this process so far, MiB (Linux VmHWM).
double peakResidentMemoryMiB();
// Whether the kernel gives transparent huge pages to a program that asks (/sys/kernel/mm/transparent_hugepage/enabled
// is "always" or "madvise"; false if unreadable). Thread-safe; never throws.
bool transparentHugePagesAvailable();
// Whether this process's glibc was started with its whole heap in transparent huge pages: GLIBC_TUNABLES holds
// glibc.malloc.hugetlb=1 and glibc.malloc.arena_max=1 (one arena, the main heap, which alone glibc madvises; the CLI
// restarts itself with both, cli/huge_page_heap.h), and transparentHugePagesAvailable(). Thread-safe; never throws.
bool heapInHugePages();
// The two glibc tunables heapInHugePages() reads and the CLI's restart sets, each to 1.
inline constexpr const char* kGlibcHugePageTunable = "glibc.malloc.hugetlb";
inline constexpr const char* kGlibcArenaCountTunable = "glibc.malloc.arena_max";

}  // namespace hemibake
