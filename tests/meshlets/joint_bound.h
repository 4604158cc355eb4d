/*
 * joint_bound.h - a lower bound on the summed palette sizes (distinct joints per meshlet, summed
 * over meshlets) of ANY split of a mesh into meshlets within the given limits. Divided by a
 * meshlet count it bounds the mean joints per meshlet of every split with at most that many
 * meshlets; the meshlet benchmark uses it to tell a target out of reach from one not yet met.
 */
#ifndef SKINPACK_TEST_JOINT_BOUND_H
#define SKINPACK_TEST_JOINT_BOUND_H

#include "meshlet_check.h"

typedef struct joint_bound {
    size_t by_influence_count; /* sum over n of the meshlets that must hold a vertex of >= n influences */
    size_t by_joint;           /* sum over joints of the meshlets that must hold the joint */
    size_t forced_splits;      /* groups of single-meshlet joints that cannot share one meshlet */
    size_t palette_sum;        /* the bound: max(by_influence_count, by_joint + forced_splits) */
} joint_bound;

/* Returns 0 when out of memory. Joints are counted where the weight is > 0, as sp_build_meshlets
 * counts them; triangles are the index buffer's (every meshlet split keeps each exactly once). */
int joint_bound_compute(const meshlet_input* in, size_t max_vertices, size_t max_triangles, joint_bound* out);

#endif
