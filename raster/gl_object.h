#pragma once
// Owning handle for one GL object. Deletion binds the owning context first (a no-op on the thread that is
// already using it), so objects can die after their creator's Binding has ended.
#include <string_view>
#include <utility>

#include "raster/gl_context.h"

namespace hemibake {

enum class GlObjectKind { Buffer, Texture, Renderbuffer, Framebuffer, VertexArray, Program };

class GlObject {
public:
    GlObject() = default;
    // Creates the object; `context` must be bound on the calling thread.
    GlObject(const GlContext& context, GlObjectKind kind);
    ~GlObject() { reset(); }
    GlObject(GlObject&& other) noexcept
        : context_(std::exchange(other.context_, nullptr)), kind_(other.kind_), id_(std::exchange(other.id_, 0)) {}
    GlObject& operator=(GlObject&& other) noexcept {
        if (this != &other) {
            reset();
            context_ = std::exchange(other.context_, nullptr);
            kind_ = other.kind_;
            id_ = std::exchange(other.id_, 0);
        }
        return *this;
    }
    GlObject(const GlObject&) = delete;
    GlObject& operator=(const GlObject&) = delete;

    GLuint id() const { return id_; }
    void reset() noexcept;

private:
    const GlContext* context_ = nullptr;
    GlObjectKind kind_ = GlObjectKind::Buffer;
    GLuint id_ = 0;
};

// Compiles and links a vertex + fragment program; throws GlError with `name` and the info log on failure.
GlObject compileProgram(const GlContext& context, std::string_view name, const char* vertexSource,
                        const char* fragmentSource);

}  // namespace hemibake
