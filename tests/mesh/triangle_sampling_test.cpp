// mesh/triangle_sampling.h: the sub-triangles points are drawn in are the ones forEachSubTriangleCentroid visits, in
// its order (a known answer: u1 = 4/9, u2 = 1/2 maps a triangle's uniform sample to its centroid), and every point
// lies in its own sub-triangle.
#include <gtest/gtest.h>

#include <vector>

#include "mesh/triangle_sampling.h"

using namespace hemibake;

TEST(TriangleSampling, PointInSubTriangleAtTheCentroidUniformsIsThatSubTrianglesCentroid) {
    for (const int k : {1, 2, 3, 5, 16}) {
        std::vector<glm::dvec2> centroids;
        forEachSubTriangleCentroid(k, [&](double wa, double wb) { centroids.emplace_back(wa, wb); });
        ASSERT_EQ(centroids.size(), std::size_t(k * k));
        for (int index = 0; index < k * k; ++index) {
            const glm::dvec2 p = pointInSubTriangle(k, index, 4.0 / 9.0, 0.5);
            EXPECT_NEAR(p.x, centroids[index].x, 1e-12) << "k " << k << " index " << index;
            EXPECT_NEAR(p.y, centroids[index].y, 1e-12) << "k " << k << " index " << index;
        }
    }
}

TEST(TriangleSampling, PointsStayInTheirSubTriangle) {
    const int k = 4;
    std::vector<glm::dvec2> centroids;
    forEachSubTriangleCentroid(k, [&](double wa, double wb) { centroids.emplace_back(wa, wb); });
    for (int index = 0; index < k * k; ++index)
        for (const double u1 : {0.0, 0.3, 0.999999})
            for (const double u2 : {0.0, 0.5, 0.999999}) {
                const glm::dvec2 p = pointInSubTriangle(k, index, u1, u2);
                // Inside the whole triangle, and in the cell (row ⌊k·wa⌋, column ⌊k·wb⌋) of its sub-triangle, on
                // the same side of that cell's diagonal as the sub-triangle's centroid.
                EXPECT_GE(p.x, -1e-12);
                EXPECT_GE(p.y, -1e-12);
                EXPECT_LE(p.x + p.y, 1.0 + 1e-12);
                const glm::dvec2 c = centroids[index] * double(k), q = p * double(k);
                const double cellX = std::floor(c.x), cellY = std::floor(c.y);
                EXPECT_GE(q.x, cellX - 1e-9);
                EXPECT_LE(q.x, cellX + 1.0 + 1e-9);
                EXPECT_GE(q.y, cellY - 1e-9);
                EXPECT_LE(q.y, cellY + 1.0 + 1e-9);
                const bool upright = (c.x - cellX) + (c.y - cellY) < 1.0;
                if (upright) EXPECT_LE((q.x - cellX) + (q.y - cellY), 1.0 + 1e-9) << index;
                else EXPECT_GE((q.x - cellX) + (q.y - cellY), 1.0 - 1e-9) << index;
            }
}
