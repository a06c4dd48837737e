#pragma once
// The editing structure for one baked surface: an OpenMesh triangle mesh in world space (double precision,
// so scenes far from the origin keep their millimetres), with the attributes the later stages need.
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <glm/glm.hpp>

namespace hemibake {

struct SurfaceMeshTraits : public OpenMesh::DefaultTraits {
    using Point = OpenMesh::Vec3d;
    using Normal = OpenMesh::Vec3d;
    using TexCoord2D = OpenMesh::Vec2f;  // TEXCOORD_0: the base-colour texture's coordinates
    VertexAttributes(OpenMesh::Attributes::Normal | OpenMesh::Attributes::TexCoord2D | OpenMesh::Attributes::Status);
    FaceAttributes(OpenMesh::Attributes::Normal | OpenMesh::Attributes::Status);
    EdgeAttributes(OpenMesh::Attributes::Status);
    HalfedgeAttributes(OpenMesh::Attributes::PrevHalfedge);
};

using TriMesh = OpenMesh::TriMesh_ArrayKernelT<SurfaceMeshTraits>;

inline glm::dvec3 toGlm(const OpenMesh::Vec3d& p) { return {p[0], p[1], p[2]}; }

// Per-vertex lightmap UV (TEXCOORD_1) and per-face material/instance ids live in named properties so that
// OpenMesh's split/copy operations carry them along.
class SurfaceMesh : public TriMesh {
public:
    SurfaceMesh() {
        add_property(lightmapUvProp, "hemibake:uv1");
        add_property(materialProp, "hemibake:material");
        add_property(instanceProp, "hemibake:instance");
        add_property(sourceFaceProp, "hemibake:source_face");
        add_property(sourceVertexProp, "hemibake:source_vertex");
    }
    SurfaceMesh(const SurfaceMesh&) = default;
    SurfaceMesh(SurfaceMesh&&) = default;
    SurfaceMesh& operator=(const SurfaceMesh&) = default;
    SurfaceMesh& operator=(SurfaceMesh&&) = default;

    OpenMesh::Vec2f& lightmapUv(VertexHandle v) { return property(lightmapUvProp, v); }
    const OpenMesh::Vec2f& lightmapUv(VertexHandle v) const { return property(lightmapUvProp, v); }
    int& material(FaceHandle f) { return property(materialProp, f); }
    int material(FaceHandle f) const { return property(materialProp, f); }
    int& instance(FaceHandle f) { return property(instanceProp, f); }
    int instance(FaceHandle f) const { return property(instanceProp, f); }
    // Index of the triangle as it was loaded (before any subdivision), for writing results back.
    int& sourceFace(FaceHandle f) { return property(sourceFaceProp, f); }
    int sourceFace(FaceHandle f) const { return property(sourceFaceProp, f); }

    // Index of the glTF vertex (in the primitive's accessors) this vertex was made from, for writing results back.
    // A glTF vertex may have several SurfaceMesh vertices (non-manifold sheets); each has one glTF vertex.
    int& sourceVertex(VertexHandle v) { return property(sourceVertexProp, v); }
    int sourceVertex(VertexHandle v) const { return property(sourceVertexProp, v); }

    // Adds a vertex at p with zero normal, texture and lightmap coordinates. Hides TriMesh::add_vertex because
    // OpenMesh's vectors default-construct uninitialised (VectorT() {}): a vertex whose attributes a loader does not
    // set would otherwise read stack garbage (a NaN TEXCOORD_0 in a textured furnace made the path tracer NaN on CI).
    VertexHandle add_vertex(const Point& p) {
        const VertexHandle v = TriMesh::add_vertex(p);
        set_normal(v, Normal(0.0));
        set_texcoord2D(v, TexCoord2D(0.0f));
        lightmapUv(v) = OpenMesh::Vec2f(0.0f);
        return v;
    }

    double faceArea(FaceHandle f) const;

private:
    OpenMesh::VPropHandleT<OpenMesh::Vec2f> lightmapUvProp;
    OpenMesh::FPropHandleT<int> materialProp;
    OpenMesh::FPropHandleT<int> instanceProp;
    OpenMesh::FPropHandleT<int> sourceFaceProp;
    OpenMesh::VPropHandleT<int> sourceVertexProp;
};

}  // namespace hemibake
