/*
 * meshlets_naive.c - baseline 1, the thesis's naive builder (listing A.1): walk the triangles
 * in index order and close the meshlet as soon as the next triangle would break a limit. The
 * palette limit is checked as well, so its meshlets obey the same contract as ours.
 */
#include "meshlets_internal.h"

void sp_meshlets_build_naive(sp_meshlet_context* ctx)
{
    sp_meshlet_greedy(ctx, NULL, ctx->triangle_count);
}
