#include "mesh/subdivision.h"

#include <algorithm>
#include <cmath>

namespace hemibake {

namespace {

glm::dvec3 toGlm(const OpenMesh::Vec3d& p) { return {p[0], p[1], p[2]}; }

double emitterPatchSize(const SubdivisionSettings& s) {
    // Emitters shoot first and at close range; a quarter of the patch size keeps the proximity error of a
    // single hemicube per patch small (GROUND_TRUTH §3.4).
    return s.emitterPatchSizeM > 0.0 ? s.emitterPatchSizeM : s.patchSizeM / 4.0;
}

// Refines a copy of one instance's mesh into patches, then elements; each face remembers its patch.
struct RefinedInstance {
    SurfaceMesh mesh;
    OpenMesh::FPropHandleT<int> patchOfFace;
    int patchCount = 0;
};

RefinedInstance refine(const MeshInstance& instance, double patchSizeM, double elementSizeM) {
    RefinedInstance r;
    r.mesh = instance.mesh;
    r.mesh.add_property(r.patchOfFace);
    bisectLongEdges(r.mesh, patchSizeM);
    for (auto f : r.mesh.faces()) r.mesh.property(r.patchOfFace, f) = f.idx();
    r.patchCount = int(r.mesh.n_faces());
    bisectLongEdges(r.mesh, std::min(elementSizeM, patchSizeM));
    return r;
}

void validate(const SubdivisionSettings& s) {
    if (!(s.patchSizeM > 0.0) || !std::isfinite(s.patchSizeM)) throw std::invalid_argument("patch size must be > 0");
    if (!(s.elementSizeM > 0.0) || !std::isfinite(s.elementSizeM)) throw std::invalid_argument("element size must be > 0");
    if (s.emitterPatchSizeM < 0.0) throw std::invalid_argument("emitter patch size must be >= 0");
}

}  // namespace

std::size_t bisectLongEdges(SurfaceMesh& mesh, double maxEdgeM) {
    // An edge exactly at the limit must not split on rounding alone (it would, 1e5 m from the origin), so the
    // limit carries a relative tolerance far above double rounding and far below any meaningful length.
    const double limit2 = maxEdgeM * maxEdgeM * (1.0 + 1e-6);
    std::size_t splits = 0;
    for (bool changed = true; changed;) {
        changed = false;
        const std::size_t faceCount = mesh.n_faces();  // faces created in this pass are visited in the next
        for (std::size_t i = 0; i < faceCount; ++i) {
            const SurfaceMesh::FaceHandle f{int(i)};
            SurfaceMesh::HalfedgeHandle longest;
            double longest2 = limit2;
            for (auto h : mesh.fh_range(f)) {
                const double len2 = mesh.calc_edge_sqr_length(h);
                if (len2 > longest2) {
                    longest2 = len2;
                    longest = h;
                }
            }
            if (!longest.is_valid()) continue;
            const auto a = mesh.from_vertex_handle(longest), b = mesh.to_vertex_handle(longest);
            const auto mid = mesh.add_vertex(0.5 * (mesh.point(a) + mesh.point(b)));
            auto n = mesh.normal(a) + mesh.normal(b);
            const double len = n.norm();
            mesh.set_normal(mid, len > 0.0 ? n / len : mesh.normal(a));
            mesh.set_texcoord2D(mid, 0.5f * (mesh.texcoord2D(a) + mesh.texcoord2D(b)));
            mesh.lightmapUv(mid) = 0.5f * (mesh.lightmapUv(a) + mesh.lightmapUv(b));
            mesh.split_edge_copy(mesh.edge_handle(longest), mid);
            ++splits;
            changed = true;
        }
    }
    mesh.update_face_normals();
    return splits;
}

PatchMesh subdivide(const Scene& scene, const SubdivisionSettings& settings) {
    validate(settings);
    PatchMesh out;
    const Bounds bounds = scene.bounds();
    out.origin = bounds.centre();
    out.sceneDiagonalM = bounds.diagonal();
    ElementArrays& el = out.elements;
    PatchArrays& pa = out.patches;

    for (std::size_t instIndex = 0; instIndex < scene.instances.size(); ++instIndex) {
        const MeshInstance& instance = scene.instances[instIndex];
        const Material& material = scene.materials[std::size_t(instance.material)];
        const double patchSize = material.isEmissive() ? std::min(settings.patchSizeM, emitterPatchSize(settings))
                                                       : settings.patchSizeM;
        RefinedInstance r = refine(instance, patchSize, settings.elementSizeM);
        const SurfaceMesh& m = r.mesh;

        // Counting sort of faces by patch, so each patch's elements are contiguous.
        std::vector<std::uint32_t> start(std::size_t(r.patchCount) + 1, 0);
        for (auto f : m.faces()) ++start[std::size_t(m.property(r.patchOfFace, f)) + 1];
        for (std::size_t p = 0; p < std::size_t(r.patchCount); ++p) start[p + 1] += start[p];
        std::vector<int> order(m.n_faces());
        {
            std::vector<std::uint32_t> cursor(start.begin(), start.end() - 1);
            for (auto f : m.faces()) order[cursor[std::size_t(m.property(r.patchOfFace, f))]++] = f.idx();
        }

        const int sides = material.doubleSided ? 2 : 1;
        for (int side = 0; side < sides; ++side) {
            const auto vertexBase = std::uint32_t(el.vertices.size());
            for (auto v : m.vertices()) {
                el.vertices.push_back(toGlm(m.point(v)));
                const auto uv = m.lightmapUv(v);
                el.vertexLightmapUv.emplace_back(uv[0], uv[1]);
            }
            for (int p = 0; p < r.patchCount; ++p) {
                const auto patchIndex = std::uint32_t(pa.size());
                const auto first = std::uint32_t(el.size());
                double patchArea = 0.0;
                glm::dvec3 areaCentroid(0.0), areaNormal(0.0), areaRho(0.0), areaLe(0.0);
                for (std::uint32_t k = start[std::size_t(p)]; k < start[std::size_t(p) + 1]; ++k) {
                    const SurfaceMesh::FaceHandle f{order[k]};
                    std::array<std::uint32_t, 3> tri{};
                    std::array<glm::vec2, 3> uv0{};
                    int c = 0;
                    for (auto v : m.fv_range(f)) {
                        tri[std::size_t(c)] = vertexBase + std::uint32_t(v.idx());
                        const auto t = m.texcoord2D(v);
                        uv0[std::size_t(c)] = {t[0], t[1]};
                        ++c;
                    }
                    if (side == 1) std::swap(tri[1], tri[2]);
                    const glm::dvec3 a = el.vertices[tri[0]], b = el.vertices[tri[1]], cc = el.vertices[tri[2]];
                    const glm::dvec3 cross = glm::cross(b - a, cc - a);
                    const double area = 0.5 * glm::length(cross);
                    const glm::dvec3 n = area > 0.0 ? cross / (2.0 * area) : glm::dvec3(0.0);
                    const glm::dvec3 centroid = (a + b + cc) / 3.0;
                    const glm::vec3 rho = scene.averageReflectance(instance.material, uv0[0], uv0[1], uv0[2]);
                    el.triangles.push_back(tri);
                    el.normal.push_back(glm::vec3(n));
                    el.centroid.push_back(centroid);
                    el.areaM2.push_back(area);
                    el.reflectance.push_back(rho);
                    el.emittedRadiance.push_back(material.emittedRadiance);
                    el.patch.push_back(patchIndex);
                    el.instance.push_back(std::uint32_t(instIndex));
                    el.sourceFace.push_back(std::uint32_t(m.sourceFace(f)));
                    el.backSide.push_back(std::uint8_t(side));
                    patchArea += area;
                    areaCentroid += area * centroid;
                    areaNormal += area * n;
                    areaRho += area * glm::dvec3(rho);
                    areaLe += area * glm::dvec3(material.emittedRadiance);
                }
                const std::uint32_t count = std::uint32_t(el.size()) - first;
                if (count == 0 || !(patchArea > 0.0)) continue;  // cannot happen after degenerate removal
                const double nLen = glm::length(areaNormal);
                pa.firstElement.push_back(first);
                pa.elementCount.push_back(count);
                pa.areaM2.push_back(patchArea);
                pa.centroid.push_back(areaCentroid / patchArea);
                pa.normal.push_back(glm::vec3(nLen > 0.0 ? areaNormal / nLen : glm::dvec3(0, 0, 1)));
                pa.reflectance.push_back(glm::vec3(areaRho / patchArea));
                pa.emittedRadiance.push_back(glm::vec3(areaLe / patchArea));
                pa.instance.push_back(std::uint32_t(instIndex));
            }
        }
    }
    return out;
}

SubdivisionStats countSubdivision(const Scene& scene, const SubdivisionSettings& settings) {
    const PatchMesh pm = subdivide(scene, settings);
    SubdivisionStats s;
    s.patches = pm.patches.size();
    s.elements = pm.elements.size();
    for (std::size_t p = 0; p < pm.patches.size(); ++p) {
        const glm::vec3 le = pm.patches.emittedRadiance[p];
        if (le.x > 0.0f || le.y > 0.0f || le.z > 0.0f) {
            ++s.emitterPatches;
            s.emitterElements += pm.patches.elementCount[p];
        }
    }
    return s;
}

}  // namespace hemibake
