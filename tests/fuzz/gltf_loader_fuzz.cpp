// libFuzzer target for the glTF loader: any bytes, as .gltf or .glb, must either load or fail with an InputError
// (CONVENTIONS.md: bad input is exit 1 with a one-line message, never a crash). Anything else escaping, and every
// ASan/UBSan report, is a finding.
//
// loadGltf reads from a path (external buffers resolve against its folder), so each input is written to one temp
// file per process; the extension follows the magic bytes as a user's file would.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "fuzz_scratch_dir.h"
#include "mesh/errors.h"
#include "mesh/gltf_loader.h"

namespace {

class FuzzInputFile {
public:
    std::string write(const std::uint8_t* data, std::size_t size) {
        const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
        const std::filesystem::path path = dir_.path() / (binary ? "input.glb" : "input.gltf");
        std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
        return path.string();
    }

private:
    hemibake::fuzz::ScratchDir dir_{"hemibake-fuzz"};
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static FuzzInputFile file;  // libFuzzer's entry point has no context object to hold it
    const std::string path = file.write(data, size);
    try {
        const hemibake::Scene scene = hemibake::loadGltf(path);
        (void)scene.triangleCount();
    } catch (const hemibake::InputError&) {
        // the expected way to reject bad input
    }
    return 0;
}
