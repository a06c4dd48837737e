#pragma once
// The whole bake, one entry point: solve, probes and volume, lightmaps, and the files of CONVENTIONS.md "Bake
// output layout". Load-independent: the caller loads the scene (mesh/gltf_loader.h) and says where it came from.
#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "baker/lightmap/lightmap.h"
#include "baker/pipeline/bake_report.h"
#include "baker/pipeline/bake_settings.h"
#include "baker/solve/solve_scene.h"
#include "mesh/scene.h"
#include "mesh/texels.h"
#include "mesh/uv_atlas.h"

namespace hemibake {

struct BakeProgressEvent {
    enum class Kind {
        Update,     // transient: what is running now ("lightmaps: 1200 / 34604 texels")
        Step,       // transient, a new step begins ("preparing: room scale"): show it even if an update was just shown,
                    // or a long step could run under the name of the short one before it
        StageDone,  // a stage's one-line summary
        Warning,    // something the user should know (clamped input, a fallback); also in bake.json
    };
    Kind kind = Kind::Update;
    std::string message;
};
// Called on the baking thread, often (throttle in the callback). Return false to cancel the bake.
using BakeProgress = std::function<bool(const BakeProgressEvent&)>;

// Thrown by bakeScene when the progress callback asked to cancel. Nothing is left in the output folder that was
// not there before the bake (every file is written atomically; files already written stay).
class BakeCancelled : public std::runtime_error {
public:
    BakeCancelled() : std::runtime_error("bake cancelled") {}
};

struct BakeOutput {
    std::string scenePath;          // the glTF `scene` was loaded from: the glb writer re-reads it
    std::filesystem::path dir;      // OUT/; empty = keep the results in memory only
    double loadSeconds = 0.0;       // time the caller spent loading `scene` (bake.json timings.load)
};

struct BakeResult {
    BakeReport report;                         // what bake.json says (written when BakeOutput::dir is set)
    std::unique_ptr<SolvedScene> solved;
    UvAtlas atlas;
    std::vector<AtlasTexels> texels;           // per atlas
    std::vector<LightmapImage> lightmaps;      // per atlas, E/π, dilated and stitched
};

// Bakes `scene` with `settings` (texelsPerUnit 0 = the preset's density for this scene). Throws InputError
// naming the file for bad input (probe positions file), std::invalid_argument for bad settings, BakeCancelled,
// and std::runtime_error when an output cannot be written. Uses every core (settings.solve.solver.threads caps
// it); one bake at a time per process (GL contexts are per worker thread).
BakeResult bakeScene(const Scene& scene, const BakeSettings& settings, const BakeOutput& output,
                     const BakeProgress& progress = {});

}  // namespace hemibake
