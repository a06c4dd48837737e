#include "raster/hemicube.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "mesh/frame_math.h"
#include "raster/chunk_culling.h"
#include "raster/reversed_z.h"

namespace hemibake {

namespace {

// The two sides of a double-sided surface are coincident elements with opposite winding, so their depths tie
// (or differ by interpolation ulps, depending on vertex order). A back-facing triangle is pushed back by
// 2^-20 of its depth (16 float ulps), so the side facing the eye wins regardless of draw order. Done in the
// vertex stage from the element normal: writing gl_FragDepth instead disables llvmpipe's early depth test and
// costs ~30 % of a 10k-triangle hemicube.
const char* kHemicubeVertexShader = R"(#version 330 core
layout(location = 0) in vec3 positionRelOrigin;
layout(location = 1) in uint elementId;
layout(location = 2) in vec3 elementNormal;
layout(location = 3) in vec3 lightmapUvLayer;
uniform vec3 eyeRelOrigin;
uniform mat3 faceRows;   // rows: right, up, forward of this face
uniform vec2 yTransform; // clip.y = up*x - forward*y: (1,0) full face, (2,1) upper half of a side face
uniform float nearM;
flat out uint element;
out vec2 lightmapUv;
flat out float lightmapLayer;
void main() {
    vec3 toEye = eyeRelOrigin - positionRelOrigin;
    vec3 v = faceRows * -toEye;
    bool backFacing = dot(elementNormal, toEye) < 0.0;
    // Reversed-Z with an infinite far plane: depth = near/forward, never clipped far away.
    gl_Position = vec4(v.x, v.y * yTransform.x - v.z * yTransform.y,
                       backFacing ? nearM * (1.0 - 1.0 / 1048576.0) : nearM, v.z);
    element = elementId;
    lightmapUv = lightmapUvLayer.xy;
    lightmapLayer = lightmapUvLayer.z;
}
)";

const char* kItemFragmentShader = R"(#version 330 core
flat in uint element;
layout(location = 0) out uint item;
void main() { item = gl_FrontFacing ? element : 0xFFFFFFFEu; }
)";

// Alpha tags the pixel class for the fractions: 0 sky (clear value), 1 front hit, 2 back face. With a TexelLight
// (SceneBuffers::setTexelLight) a fragment adds its element's scale times the light atlas at its lightmap UV.
const char* kRadianceFragmentShader = R"(#version 330 core
flat in uint element;
in vec2 lightmapUv;
flat in float lightmapLayer;
uniform samplerBuffer elementRadiance;
uniform samplerBuffer texelLightScale;
uniform sampler2DArray texelLight;
uniform bool texelLightOn;
layout(location = 1) out vec4 radiance;
void main() {
    if (!gl_FrontFacing) {
        radiance = vec4(0.0, 0.0, 0.0, 2.0);
        return;
    }
    vec3 l = texelFetch(elementRadiance, int(element)).rgb;
    if (texelLightOn && lightmapLayer >= 0.0)
        l += texelFetch(texelLightScale, int(element)).rgb * texture(texelLight, vec3(lightmapUv, lightmapLayer)).rgb;
    radiance = vec4(l, 1.0);
}
)";

}  // namespace

HemicubeFrame HemicubeFrame::randomlyRotated(const glm::dvec3& position, const glm::dvec3& normal, std::uint64_t seed) {
    const double unit = static_cast<double>(splitMix64(seed) >> 11) * 0x1.0p-53;
    return HemicubeFrame{position, normal, 2.0 * std::numbers::pi * unit};
}

void HemicubeFrame::tangentFrame(glm::dvec3& tangent, glm::dvec3& bitangent) const {
    const glm::dvec3 n = glm::normalize(normal);
    // Duff et al. 2017, "Building an orthonormal basis, revisited": continuous except at n.z = 0 sign flips.
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double b = n.x * n.y * a;
    const glm::dvec3 t0(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    const glm::dvec3 b0 = glm::cross(n, t0);
    const double c = std::cos(rotationRadians), s = std::sin(rotationRadians);
    tangent = glm::normalize(c * t0 + s * b0);
    bitangent = glm::cross(n, tangent);
}

double FormFactorList::sum() const {
    double total = 0.0;
    for (double f : formFactors) total += f;
    return total;
}

void FormFactorList::clear() {
    elements.clear();
    formFactors.clear();
    skyFraction = backfaceFraction = 0.0;
    minDepthM = std::numeric_limits<double>::infinity();
}

HemicubeRenderer::HemicubeRenderer(const SceneBuffers& scene, int resolution, const OcclusionCullingSettings& occlusion)
    : scene_(&scene), weights_(resolution), eyeOffsetM_(kEyeOffsetPerDiagonal * scene.sceneDiagonalM()),
      nearPlaneM_(kNearPlanePerEyeOffset * eyeOffsetM_), occlusion_(occlusion) {
    const SceneIslands& islands = scene.islands();
    if (islands.size() > 1)
        for (std::size_t k = 0; k < islands.size(); ++k)
            islandEyeOffsetM_.push_back(islands.lengthM(k, kEyeOffsetPerDiagonal, kEyeOffsetFloatSteps));
    const GlContext& context = scene.context();
    if (context.majorVersion() * 10 + context.minorVersion() < 45 && !context.hasExtension("GL_ARB_clip_control"))
        throw GlError("HemicubeRenderer needs OpenGL 4.5 or GL_ARB_clip_control (reversed-Z); the context is " +
                      context.rendererName() + " " + std::to_string(context.majorVersion()) + "." +
                      std::to_string(context.minorVersion()));
    auto bound = context.bind();
    const GlFunctions& gl = context.gl();
    const int width = weights_.atlasWidth(), height = weights_.atlasHeight();

    auto renderbuffer = [&](GLenum format) {
        GlObject buffer(context, GlObjectKind::Renderbuffer);
        gl.BindRenderbuffer(GL_RENDERBUFFER, buffer.id());
        gl.RenderbufferStorage(GL_RENDERBUFFER, format, width, height);
        return buffer;
    };
    itemBuffer_ = renderbuffer(GL_R32UI);
    radianceBuffer_ = renderbuffer(GL_RGBA32F);
    depthBuffer_ = renderbuffer(GL_DEPTH_COMPONENT32F);
    gl.BindRenderbuffer(GL_RENDERBUFFER, 0);
    framebuffer_ = GlObject(context, GlObjectKind::Framebuffer);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer_.id());
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, itemBuffer_.id());
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_RENDERBUFFER, radianceBuffer_.id());
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depthBuffer_.id());
    const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        throw GlError("HemicubeRenderer: atlas framebuffer " + std::to_string(width) + "x" + std::to_string(height) +
                      " incomplete (status " + std::to_string(status) + ")");

    itemProgram_ = compileProgram(context, "hemicube item buffer", kHemicubeVertexShader, kItemFragmentShader);
    radianceProgram_ = compileProgram(context, "hemicube radiance buffer", kHemicubeVertexShader, kRadianceFragmentShader);
    auto locate = [&](const GlObject& program) {
        Uniforms u;
        u.eye = gl.GetUniformLocation(program.id(), "eyeRelOrigin");
        u.faceRows = gl.GetUniformLocation(program.id(), "faceRows");
        u.yTransform = gl.GetUniformLocation(program.id(), "yTransform");
        u.nearM = gl.GetUniformLocation(program.id(), "nearM");
        u.radiance = gl.GetUniformLocation(program.id(), "elementRadiance");
        u.texelLight = gl.GetUniformLocation(program.id(), "texelLight");
        u.texelLightScale = gl.GetUniformLocation(program.id(), "texelLightScale");
        u.texelLightOn = gl.GetUniformLocation(program.id(), "texelLightOn");

        return u;
    };
    itemUniforms_ = locate(itemProgram_);
    radianceUniforms_ = locate(radianceProgram_);
    gl.UseProgram(radianceProgram_.id());
    gl.Uniform1i(radianceUniforms_.radiance, 0);
    gl.Uniform1i(radianceUniforms_.texelLightScale, 1);
    gl.Uniform1i(radianceUniforms_.texelLight, 2);
    gl.UseProgram(0);
    gl.check(("HemicubeRenderer: creating the R=" + std::to_string(resolution) + " atlas").c_str());

    ids_.resize(weights_.pixelCount());
    depths_.resize(weights_.pixelCount());
    radiance_.resize(weights_.pixelCount());
    accumulator_.assign(scene.elementCount(), 0.0);
    chunkFaces_.resize(scene.chunks().size());
    chunkOccluderRound_.resize(scene.chunks().size());
    nodeFaces_.resize(scene.chunkTree().size());
    occluderCandidates_.reserve(scene.chunks().size());
    liveChunks_.reserve(scene.chunks().size());
    runs_.firsts.reserve(scene.chunks().size());
    runs_.counts.reserve(scene.chunks().size());
}

constexpr std::uint8_t kAllFaces = (1u << HemicubeWeights::kFaceCount) - 1u;

void HemicubeRenderer::draw(const HemicubeFrame& frame, Target target, glm::vec3 skyRadiance) {
    const GlFunctions& gl = scene_->context().gl();
    const bool items = target == Target::Items;
    const Uniforms& uniforms = items ? itemUniforms_ : radianceUniforms_;

    glm::dvec3 tangent, bitangent;
    frame.tangentFrame(tangent, bitangent);
    const glm::dvec3 normal = glm::normalize(frame.normal);
    eyeOffsetM_ = eyeOffsetAtM(frame.position);
    nearPlaneM_ = kNearPlanePerEyeOffset * eyeOffsetM_;
    const glm::vec3 eye(frame.position + eyeOffsetM_ * normal - scene_->origin());

    // Per face: the frame, and per chunk the faces whose frustum its box reaches (CPU culling).
    const auto chunks = scene_->chunks();
    const float slack = chunkBoundsSlack(*scene_);
    const glm::dvec3 forwards[HemicubeWeights::kFaceCount] = {normal, tangent, -tangent, bitangent, -bitangent};
    FaceProjection faces[HemicubeWeights::kFaceCount];
    glm::vec3 planes[HemicubeWeights::kFaceCount][4];
    for (int face = 0; face < HemicubeWeights::kFaceCount; ++face) {
        const glm::dvec3 f = forwards[face];
        const glm::dvec3 u = face == 0 ? bitangent : normal;
        const glm::dvec3 r = glm::cross(f, u);  // makes counter-clockwise-from-the-front triangles front-facing
        faces[face] = FaceProjection{glm::vec3(r), glm::vec3(u), glm::vec3(f), face == 0 ? 1.0f : 2.0f,
                                     face == 0 ? 0.0f : 1.0f, weights_.faceViewport(face)};
        // Frustum side planes through the eye (inside where plane·(p − eye) ≥ 0); the near plane is left to
        // the clipper. Side faces keep only their upper half: the bottom plane is the horizon.
        planes[face][0] = glm::vec3(f - r);
        planes[face][1] = glm::vec3(f + r);
        planes[face][2] = glm::vec3(f - u);
        planes[face][3] = face == 0 ? glm::vec3(f + u) : glm::vec3(u);
    }
    const glm::vec3 horizon(normal);
    // A box wholly inside one face's frustum (by more than the slack) has pixels on no other face, and neither has
    // anything inside it: its subtree is settled without descending (most of a level lies in such boxes).
    auto inFrustum = [&](std::uint32_t, const SceneBuffers::ChunkNode& node, std::uint8_t faceMask) {
        if (maxAlongPlane(horizon, node.boundsMin, node.boundsMax, eye) < -slack) return std::uint8_t(0);
        for (int face = 0; face < HemicubeWeights::kFaceCount; ++face) {
            if (!(faceMask >> face & 1u)) continue;
            bool inside = true;
            for (const glm::vec3& plane : planes[face]) {
                if (maxAlongPlane(plane, node.boundsMin, node.boundsMax, eye) < -slack) {
                    faceMask &= std::uint8_t(~(1u << face));
                    inside = false;
                    break;
                }
                inside = inside && minAlongPlane(plane, node.boundsMin, node.boundsMax, eye) > slack;
            }
            if (inside && minAlongPlane(horizon, node.boundsMin, node.boundsMax, eye) > slack)
                return std::uint8_t((1u << face) | kSubtreeSettled);
        }
        return faceMask;
    };
    liveChunks_.clear();
    auto assignFaces = [&](const SceneBuffers::ChunkNode& node, std::uint8_t faceMask) {
        std::fill_n(chunkFaces_.begin() + node.firstChunk, node.chunkCount, faceMask);
        if (faceMask)  // the tree lists its chunks in order: liveChunks_ stays ascending
            for (std::uint32_t c = node.firstChunk; c < node.firstChunk + node.chunkCount; ++c) liveChunks_.push_back(c);
    };
    if (!chunks.empty()) cullChunkTree(scene_->chunkTree(), 0, kAllFaces, inFrustum, assignFaces);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer_.id());
    gl.BindVertexArray(scene_->vertexArray());
    ++drawTotals_.hemicubes;

    const GLenum drawBuffers[2] = {items ? GLenum(GL_COLOR_ATTACHMENT0) : GLenum(GL_NONE),
                                   items ? GLenum(GL_NONE) : GLenum(GL_COLOR_ATTACHMENT1)};
    gl.DrawBuffers(2, drawBuffers);
    beginReversedZPass(gl);
    if (items) {
        const GLuint sky[4] = {kSkyId, 0, 0, 0};
        gl.ClearBufferuiv(GL_COLOR, 0, sky);
    } else {
        const GLfloat sky[4] = {skyRadiance.x, skyRadiance.y, skyRadiance.z, 0.0f};
        gl.ClearBufferfv(GL_COLOR, 1, sky);
    }
    gl.Enable(GL_SCISSOR_TEST);  // guard-band rasterisers may otherwise spill into a neighbouring face

    gl.UseProgram(items ? itemProgram_.id() : radianceProgram_.id());
    gl.Uniform3f(uniforms.eye, eye.x, eye.y, eye.z);
    gl.Uniform1f(uniforms.nearM, static_cast<float>(nearPlaneM_));
    if (!items) {
        gl.ActiveTexture(GL_TEXTURE0);
        gl.BindTexture(GL_TEXTURE_BUFFER, scene_->radianceTexture());
        gl.Uniform1i(uniforms.texelLightOn, scene_->hasTexelLight() ? 1 : 0);
        if (scene_->hasTexelLight()) {
            gl.ActiveTexture(GL_TEXTURE1);
            gl.BindTexture(GL_TEXTURE_BUFFER, scene_->texelLightScaleTexture());
            gl.ActiveTexture(GL_TEXTURE2);
            gl.BindTexture(GL_TEXTURE_2D_ARRAY, scene_->texelLightTexture());
            gl.ActiveTexture(GL_TEXTURE0);
        }
    }
    // Occluders are drawn shaded, into the same buffers, before the rest: each chunk is drawn once.
    std::fill(chunkOccluderRound_.begin(), chunkOccluderRound_.end(), std::uint8_t(0));
    lastChunksDrawn_ = 0;
    if (occlusion_.enabled && chunks.size() >= occlusion_.minChunks)
        lastChunksDrawn_ += cullOccludedChunks(eye, faces, uniforms);
    for (int face = 0; face < HemicubeWeights::kFaceCount; ++face)
        lastChunksDrawn_ += drawChunks(
            faces[face], uniforms, liveChunks_,
            [&](std::size_t c) { return chunkOccluderRound_[c] == 0 && (chunkFaces_[c] >> face & 1u); },
            drawTotals_.triangles);
    gl.BindVertexArray(0);
    gl.UseProgram(0);
}

template <class Keep>
std::size_t HemicubeRenderer::drawChunks(const FaceProjection& face, const Uniforms& uniforms,
                                         std::span<const std::uint32_t> list, Keep keep, std::uint64_t& triangles) {
    const GlFunctions& gl = scene_->context().gl();
    const auto chunks = scene_->chunks();
    runs_.clear();
    std::size_t drawn = 0;
    for (const std::uint32_t c : list) {
        if (!keep(c)) continue;
        ++drawn;
        triangles += std::uint64_t(chunks[c].vertexCount) / 3;
        runs_.add(chunks[c]);
    }
    if (drawn == 0) return 0;
    const GLfloat rows[9] = {face.right.x, face.right.y, face.right.z, face.up.x,     face.up.y,
                             face.up.z,    face.forward.x, face.forward.y, face.forward.z};
    gl.UniformMatrix3fv(uniforms.faceRows, 1, GL_TRUE, rows);
    gl.Uniform2f(uniforms.yTransform, face.yScale, face.yOffset);
    const PixelRect& vp = face.viewport;
    gl.Viewport(vp.x, vp.y, vp.width, vp.height);
    gl.Scissor(vp.x, vp.y, vp.width, vp.height);
    runs_.draw(gl);
    return drawn;
}

std::size_t HemicubeRenderer::cullOccludedChunks(const glm::vec3& eye,
                                                 const FaceProjection (&faces)[HemicubeWeights::kFaceCount],
                                                 const Uniforms& uniforms) {
    const auto chunks = scene_->chunks();
    // Occluders in order of how large they look: area / squared distance to the box (the eye inside a box puts it
    // first), among the chunks some face draws. On level_small this beat nearest-first by ~15 % per hemicube
    // (bench_hemicube BM_LevelHemicubes): near chunks are often the other side of the wall the eye stands by.
    occluderCandidates_.clear();
    for (const std::uint32_t c : liveChunks_) {
        const glm::vec3 gap = glm::max(glm::max(chunks[c].boundsMin - eye, eye - chunks[c].boundsMax), glm::vec3(0.0f));
        const float distance2 = glm::dot(gap, gap);
        const float largeness = distance2 > 0.0f ? chunks[c].areaM2 / distance2 : std::numeric_limits<float>::max();
        occluderCandidates_.emplace_back(-largeness, c);
    }
    std::size_t batch =
        std::max<std::size_t>(1, static_cast<std::size_t>(occlusion_.occluderFraction * double(chunks.size())));
    if (occluderCandidates_.size() <= 2 * batch) return 0;  // little left to hide: draw everything in one pass

    const GlFunctions& gl = scene_->context().gl();
    const auto tree = scene_->chunkTree();
    ++drawTotals_.occlusionCulledHemicubes;
    const float slack = chunkBoundsSlack(*scene_);
    const float nearM = static_cast<float>(nearPlaneM_);

    // Rounds: draw the next batch of largest-looking chunks not yet hidden (accumulating), read the depth back, hide
    // what lies behind it and drop it from the candidates; batches double. Whatever is left after the last round is
    // drawn by the caller. A batch is drawn in chunk order, so it is selected (nth_element), not sorted.
    std::size_t chunksDrawn = 0;
    std::size_t next = 0;  // candidates before it are drawn
    for (int round = 1; round <= occlusion_.rounds && next < occluderCandidates_.size(); ++round, batch *= 2) {
        const std::size_t batchEnd = std::min(next + batch, occluderCandidates_.size());
        const auto first = occluderCandidates_.begin();
        std::nth_element(first + std::ptrdiff_t(next), first + std::ptrdiff_t(batchEnd), occluderCandidates_.end());
        batchChunks_.clear();
        for (; next < batchEnd; ++next) {
            chunkOccluderRound_[occluderCandidates_[next].second] = static_cast<std::uint8_t>(round);
            batchChunks_.push_back(occluderCandidates_[next].second);
        }
        std::sort(batchChunks_.begin(), batchChunks_.end());
        std::uint64_t triangles = 0;
        for (int face = 0; face < HemicubeWeights::kFaceCount; ++face)
            chunksDrawn += drawChunks(faces[face], uniforms, batchChunks_,
                                      [&](std::size_t c) { return chunkFaces_[c] >> face & 1u; }, triangles);
        drawTotals_.triangles += triangles;
        drawTotals_.occluderTriangles += triangles;
        gl.ReadPixels(0, 0, weights_.atlasWidth(), weights_.atlasHeight(), GL_DEPTH_COMPONENT, GL_FLOAT,
                      depths_.data());
        depthPyramid_.build(depths_, weights_.atlasWidth(), weights_.atlasHeight());
        // Down the chunk tree, over the faces some not-yet-drawn chunk of the subtree is still drawn on.
        for (std::size_t n = tree.size(); n-- > 0;) {
            const SceneBuffers::ChunkNode& node = tree[n];
            nodeFaces_[n] = node.chunkCount == 1
                                ? (chunkOccluderRound_[node.firstChunk] ? std::uint8_t(0) : chunkFaces_[node.firstChunk])
                                : std::uint8_t(nodeFaces_[n + 1] | nodeFaces_[tree[n + 1].skip]);
        }
        auto notHidden = [&](std::uint32_t n, const SceneBuffers::ChunkNode& node, std::uint8_t faceMask) {
            faceMask &= nodeFaces_[n];
            const glm::vec3 lo = node.boundsMin - slack, hi = node.boundsMax + slack;
            for (int face = 0; face < HemicubeWeights::kFaceCount; ++face)
                if ((faceMask >> face & 1u) && boxHiddenOnFace(lo, hi, eye, nearM, faces[face], depthPyramid_))
                    faceMask &= std::uint8_t(~(1u << face));
            return faceMask;
        };
        auto keepFaces = [&](const SceneBuffers::ChunkNode& node, std::uint8_t faceMask) {
            for (std::uint32_t c = node.firstChunk; c < node.firstChunk + node.chunkCount; ++c) chunkFaces_[c] &= faceMask;
        };
        cullChunkTree(tree, 0, kAllFaces, notHidden, keepFaces);
        std::size_t kept = next;
        for (std::size_t k = next; k < occluderCandidates_.size(); ++k)
            if (chunkFaces_[occluderCandidates_[k].second] != 0) occluderCandidates_[kept++] = occluderCandidates_[k];
        occluderCandidates_.resize(kept);
    }
    // What the caller draws: the chunks neither hidden nor drawn as occluders.
    std::erase_if(liveChunks_, [&](std::uint32_t c) { return chunkFaces_[c] == 0 || chunkOccluderRound_[c] != 0; });
    return chunksDrawn;
}

void HemicubeRenderer::renderFormFactors(const HemicubeFrame& frame, FormFactorList& out) {
    auto bound = scene_->context().bind();
    const GlFunctions& gl = scene_->context().gl();
    draw(frame, Target::Items, glm::vec3(0.0f));
    const int width = weights_.atlasWidth(), height = weights_.atlasHeight();
    gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl.ReadPixels(0, 0, width, height, GL_RED_INTEGER, GL_UNSIGNED_INT, ids_.data());
    gl.ReadPixels(0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, depths_.data());
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.check("HemicubeRenderer::renderFormFactors");

    out.clear();
    const std::span<const double> weights = weights_.weights();
    const std::span<const float> rayLength = weights_.rayLengthPerDepth();
    const std::uint32_t elementCount = static_cast<std::uint32_t>(accumulator_.size());
    double sky = 0.0, backface = 0.0;
    float nearest = 0.0f;  // max of depth / ray length = near / hit distance
    for (std::size_t i = 0; i < ids_.size(); ++i) {
        const std::uint32_t id = ids_[i];
        const double w = weights[i];
        if (id < elementCount) {
            if (accumulator_[id] == 0.0) out.elements.push_back(id);  // weights are > 0: zero means untouched
            accumulator_[id] += w;
        } else if (id == kSkyId) {
            sky += w;
            continue;
        } else {
            backface += w;
        }
        nearest = std::max(nearest, depths_[i] / rayLength[i]);
    }
    out.formFactors.resize(out.elements.size());
    for (std::size_t k = 0; k < out.elements.size(); ++k) {
        out.formFactors[k] = accumulator_[out.elements[k]];
        accumulator_[out.elements[k]] = 0.0;
    }
    out.skyFraction = sky;
    out.backfaceFraction = backface;
    if (nearest > 0.0f) out.minDepthM = nearPlaneM_ / static_cast<double>(nearest);
}

double HemicubeRenderer::eyeOffsetAtM(const glm::dvec3& p) const {
    if (islandEyeOffsetM_.empty()) return kEyeOffsetPerDiagonal * scene_->sceneDiagonalM();
    return islandEyeOffsetM_[scene_->islands().islandAt(p)];
}

double HemicubeRenderer::formFactorNearerThan(double distanceM) const {
    if (!(distanceM > 0.0)) return 0.0;
    // Hit distance = near × ray length / depth (see renderFormFactors): nearer than d ⇔ depth/ray length > near/d.
    const float threshold = static_cast<float>(nearPlaneM_ / distanceM);
    const std::span<const double> weights = weights_.weights();
    const std::span<const float> rayLength = weights_.rayLengthPerDepth();
    double near = 0.0;
    for (std::size_t i = 0; i < ids_.size(); ++i)
        if (ids_[i] != kSkyId && depths_[i] > threshold * rayLength[i]) near += weights[i];
    return near;
}

void HemicubeRenderer::readRadiance() {
    const GlFunctions& gl = scene_->context().gl();
    gl.ReadBuffer(GL_COLOR_ATTACHMENT1);
    gl.ReadPixels(0, 0, weights_.atlasWidth(), weights_.atlasHeight(), GL_RGBA, GL_FLOAT, radiance_.data());
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.check("HemicubeRenderer: radiance readback");
}

RadianceGather HemicubeRenderer::gatherRadiance(const HemicubeFrame& frame, glm::vec3 skyRadiance) {
    {
        auto bound = scene_->context().bind();
        draw(frame, Target::Radiance, skyRadiance);
        readRadiance();
    }
    const std::span<const double> weights = weights_.weights();
    RadianceGather result;
    for (std::size_t i = 0; i < radiance_.size(); ++i) {
        const glm::vec4& p = radiance_[i];
        const double w = weights[i];
        result.irradianceOverPi += w * glm::dvec3(p.x, p.y, p.z);
        if (p.w == 0.0f) result.skyFraction += w;
        else if (p.w == 2.0f) result.backfaceFraction += w;
    }
    return result;
}

void HemicubeRenderer::renderWeightedRadiance(const HemicubeFrame& frame, glm::vec3 skyRadiance,
                                              WeightedRadianceImage& out) {
    {
        auto bound = scene_->context().bind();
        draw(frame, Target::Radiance, skyRadiance);
        readRadiance();
    }
    const std::span<const double> weights = weights_.weights();
    out.width = weights_.atlasWidth();
    out.height = weights_.atlasHeight();
    out.pixels.resize(radiance_.size());
    for (std::size_t i = 0; i < radiance_.size(); ++i)
        out.pixels[i] = weights[i] * glm::dvec3(radiance_[i].x, radiance_[i].y, radiance_[i].z);
}

}  // namespace hemibake
