// Placeholder translation unit until the solver lands, so the baker library exists for the layers above it.
namespace hemibake {
const char* bakerVersion() { return "0.1.0"; }
}  // namespace hemibake
