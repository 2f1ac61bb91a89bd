/* test_tree_mesh.h - the small "tree" mesh the instancing tests place many
 * times (test_instance.c, test_instance_reuse.c): a UV ellipsoid of
 * TEST_TREE_RINGS x TEST_TREE_SEGS, 0.8 wide, 1 tall, 0.6 deep, standing
 * on y = 0, with its normals.
 *
 *   float pos[TEST_TREE_NV][3], nrm[TEST_TREE_NV][3];
 *   uint32_t idx[3 * TEST_TREE_NT];
 *   test_tree_mesh(pos, nrm, idx);
 */
#ifndef RT_TEST_TREE_MESH_H
#define RT_TEST_TREE_MESH_H

#include <math.h>
#include <stdint.h>

#include "rt/base/vec.h"
#include "test_util.h"

enum {
    TEST_TREE_RINGS = 4,
    TEST_TREE_SEGS = 6,
    TEST_TREE_NV = (TEST_TREE_RINGS + 1) * (TEST_TREE_SEGS + 1),
    TEST_TREE_NT = TEST_TREE_SEGS * (2 * TEST_TREE_RINGS - 2)
};

static inline void test_tree_mesh(float pos[][3], float nrm[][3], uint32_t idx[])
{
    for (int r = 0, v = 0; r <= TEST_TREE_RINGS; r++)
        for (int sg = 0; sg <= TEST_TREE_SEGS; sg++, v++) {
            double th = RT_PI * r / TEST_TREE_RINGS, ph = 2.0 * RT_PI * sg / TEST_TREE_SEGS;
            double x = sin(th) * cos(ph), y = cos(th), z = sin(th) * sin(ph);
            pos[v][0] = (float)(0.4 * x), pos[v][1] = (float)(0.5 + 0.5 * y), pos[v][2] = (float)(0.3 * z);
            nrm[v][0] = (float)x, nrm[v][1] = (float)y, nrm[v][2] = (float)z;
        }
    int ni = 0;
    for (int r = 0; r < TEST_TREE_RINGS; r++)
        for (int sg = 0; sg < TEST_TREE_SEGS; sg++) {
            uint32_t a = (uint32_t)(r * (TEST_TREE_SEGS + 1) + sg), b = a + TEST_TREE_SEGS + 1;
            if (r > 0)
                idx[ni++] = a, idx[ni++] = b, idx[ni++] = a + 1;
            if (r < TEST_TREE_RINGS - 1)
                idx[ni++] = a + 1, idx[ni++] = b, idx[ni++] = b + 1;
        }
    assert_int_equal(ni, 3 * TEST_TREE_NT);
}

#endif
