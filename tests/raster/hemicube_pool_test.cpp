// raster/hemicube_pool: per-thread contexts under tbb::parallel_for give the serial results.
#include <gtest/gtest.h>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "raster/hemicube_pool.h"
#include "support/raster_fixtures.h"

namespace hemibake {
namespace {

TEST(HemicubePool, ParallelRendersMatchSerialOnesBitForBit) {
    test::TriangleSoup soup;
    soup.addInwardBox({0, 0, 0}, {2, 1, 1}, 3);
    soup.addGrid({0.5, 0.25, 0.3}, {0.5, 0, 0}, {0, 0.5, 0}, 2);  // a floating plate for some occlusion
    const PatchMesh mesh = soup.build();
    std::vector<glm::vec3> radiance(mesh.elements.size());
    for (std::size_t e = 0; e < radiance.size(); ++e) radiance[e] = glm::vec3(float(e % 7), 1.0f, float(e % 3));

    constexpr int kFrames = 64;
    auto frame = [](int i) {
        const glm::dvec3 p(0.1 + 1.8 * (i % 8) / 8.0, 0.1 + 0.8 * (i / 8) / 8.0, 0.05);
        return HemicubeFrame::randomlyRotated(p, {0, 0, 1}, std::uint64_t(i));
    };

    HemicubePool pool(mesh, 32);
    pool.setElementRadiance(radiance);
    std::vector<FormFactorList> parallelLists(kFrames);
    std::vector<glm::dvec3> parallelGather(kFrames);
    {
        tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
        tbb::parallel_for(0, kFrames, [&](int i) {
            HemicubeRenderer& renderer = pool.local();
            renderer.renderFormFactors(frame(i), parallelLists[i]);
            parallelGather[i] = renderer.gatherIrradianceOverPi(frame(i), glm::vec3(0.0f));
        });
    }
    EXPECT_GE(pool.workerCount(), 1u);
    EXPECT_LE(pool.workerCount(), 2u);

    GlContext context;
    SceneBuffers buffers(context, mesh);
    buffers.setElementRadiance(radiance);
    HemicubeRenderer serial(buffers, 32);
    FormFactorList list;
    for (int i = 0; i < kFrames; ++i) {
        serial.renderFormFactors(frame(i), list);
        EXPECT_EQ(list.elements, parallelLists[i].elements) << i;
        EXPECT_EQ(list.formFactors, parallelLists[i].formFactors) << i;
        EXPECT_NEAR(list.sum() + list.backfaceFraction, 1.0, 1e-9);  // closed box; the plate's underside is a back face
        EXPECT_EQ(serial.gatherIrradianceOverPi(frame(i), glm::vec3(0.0f)), parallelGather[i]) << i;
    }

    // A new sweep's radiance reaches every existing worker.
    for (glm::vec3& l : radiance) l = glm::vec3(2.0f);
    pool.setElementRadiance(radiance);
    tbb::parallel_for(0, 8, [&](int i) {
        const RadianceGather g = pool.local().gatherRadiance(frame(i), glm::vec3(0.0f));
        EXPECT_NEAR(g.irradianceOverPi.x, 2.0 * (1.0 - g.backfaceFraction), 1e-6);
    });
}

TEST(HemicubePool, RejectsBadInputEarly) {
    test::TriangleSoup soup;
    soup.addQuad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0});
    const PatchMesh mesh = soup.build();
    EXPECT_THROW(HemicubePool(mesh, 31), std::invalid_argument);
    HemicubePool pool(mesh, 16);
    EXPECT_THROW(pool.setElementRadiance(std::vector<glm::vec3>(3)), GlError);
}

}  // namespace
}  // namespace hemibake
