// SurfaceMesh: a vertex starts with known attributes, whatever memory it is built in.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "mesh/surface_mesh.h"

using namespace hemibake;

// OpenMesh's vectors default-construct uninitialised. Vertices built in storage that last held NaN attributes
// (clear() keeps the capacity) must still read zero normals, TEXCOORD_0 and lightmap UVs: a loader that has no
// normals or texture coordinates for a primitive leaves them as add_vertex made them.
TEST(SurfaceMesh, NewVerticesHaveZeroNormalAndTextureCoordinates) {
    constexpr float nanF = std::numeric_limits<float>::quiet_NaN();
    constexpr double nanD = std::numeric_limits<double>::quiet_NaN();
    SurfaceMesh mesh;
    constexpr int kVertices = 64;
    for (int round = 0; round < 2; ++round) {
        for (int i = 0; i < kVertices; ++i) {
            const auto v = mesh.add_vertex({double(i), 1.0, 2.0});
            EXPECT_EQ(mesh.normal(v), SurfaceMesh::Normal(0.0)) << "round " << round << " vertex " << i;
            EXPECT_EQ(mesh.texcoord2D(v), SurfaceMesh::TexCoord2D(0.0f)) << "round " << round << " vertex " << i;
            EXPECT_EQ(mesh.lightmapUv(v), OpenMesh::Vec2f(0.0f)) << "round " << round << " vertex " << i;
            mesh.set_normal(v, SurfaceMesh::Normal(nanD));
            mesh.set_texcoord2D(v, SurfaceMesh::TexCoord2D(nanF));
            mesh.lightmapUv(v) = OpenMesh::Vec2f(nanF);
        }
        ASSERT_EQ(mesh.n_vertices(), std::size_t(kVertices));
        mesh.clear();
    }
}
