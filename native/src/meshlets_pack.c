/*
 * meshlets_pack.c - the skin builder's packing of underfull meshlets by their joints, before
 * the (spatial) merge step.
 *
 * Pieces are the plan's meshlets with room for the vertices of one more disconnected triangle
 * (sp_meshlet_vertex_room): the parts closed whole by meshlets_parts.c (which growth never
 * sees), and the few underfull meshlets growth leaves. Pieces are packed into bins, each bin
 * one group of the plan (as the merge step makes them), in two steps:
 *
 * 1. Greedy, largest piece first: each piece goes into the open bin that gains the fewest
 *    palette joints, then the fullest one (best fit), else starts a bin. Run twice, "count
 *    first" (any bin that holds the piece) and "joints first" (a new bin rather than one that
 *    gains a joint); the run with fewer bins, then fewer palette entries, is kept.
 * 2. Local search: a piece moves to another bin, or two pieces of different bins swap, where
 *    that lowers the palette sum within every limit; a bin left empty is gone (one meshlet less).
 *
 * Pieces of different parts share no vertex; two pieces of one part may share border
 * vertices, so a bin's vertex count is at most the sum of its pieces', and the sum is what is
 * checked (never over a limit). The greedy keeps PACK_BINS bins open (the fullest is closed to
 * make room) and the search runs only up to SEARCH_PIECES pieces, so the work stays linear in
 * the number of pieces on meshes made of very many small parts.
 */
#include "meshlets_internal.h"

#include <stdlib.h>
#include <string.h>

#define PACK_BINS 64         /* open bins in the greedy step */
#define SEARCH_PIECES 1024   /* the local search (quadratic in pieces) runs up to this many pieces */
#define SEARCH_PASSES 3
#define NO_PIECE UINT32_MAX

typedef struct piece {
    uint32_t meshlet;   /* plan meshlet */
    uint32_t palette;   /* its joints: pool[palette .. palette + joint_count) */
    uint32_t bin, next; /* its bin, and the next piece of that bin */
    uint16_t vertices, triangles, joint_count;
} piece;

typedef struct pack_bin {
    uint32_t first; /* first piece, NO_PIECE once the bin is empty */
    uint32_t vertices, triangles, joints;
} pack_bin;

typedef struct packer {
    const sp_meshlet_context* ctx;
    piece* pieces;
    uint32_t piece_count;
    uint16_t* pool;
    pack_bin* bins;
    uint32_t bin_count;
    uint32_t* mark; /* per joint below ctx->joint_end: stamp when marked */
    uint32_t stamp;
} packer;

size_t sp_meshlet_pack_scratch_bound(size_t triangle_count)
{
    size_t m = triangle_count; /* plan meshlets, hence pieces and bins, at most */
    /* the marks take ctx->joint_end entries; the bound is computed before any joint is seen, so it
     * counts every joint index a u16 can hold */
    return sp_meshlet_align8(m * sizeof(piece)) +
           sp_meshlet_align8(triangle_count * SP_MESHLET_TRIANGLE_JOINTS * sizeof(uint16_t)) +
           sp_meshlet_align8(m * sizeof(pack_bin)) + sp_meshlet_align8(SP_JOINT_SLOT_COUNT * sizeof(uint32_t));
}

/* The pieces, largest first (fewest free vertices, then fewest free triangles, then plan order),
 * with their palettes copied into the pool. */
static void collect_pieces(packer* p, sp_meshlet_context* ctx, const sp_meshlet_plan* plan, uint64_t* keys)
{
    uint32_t count = 0, pooled = 0;
    for (uint32_t m = 0; m < plan->count; ++m)
        if (!plan->merged[m] && sp_meshlet_vertex_room(&ctx->options, plan->vertex_count[m]))
            keys[count++] = (uint64_t)(ctx->options.max_vertices - plan->vertex_count[m]) << 42 |
                            (uint64_t)(ctx->options.max_triangles - plan->triangle_count[m]) << 32 | m;
    qsort(keys, count, sizeof(uint64_t), sp_meshlet_compare_u64);
    for (uint32_t i = 0; i < count; ++i) {
        uint32_t m = (uint32_t)keys[i];
        /* before the packing every meshlet is its own group, so the plan's counts are the piece's
         * own; only the palette is rebuilt */
        for (uint32_t k = plan->start[m]; k < plan->start[m + 1]; ++k)
            sp_meshlet_add_joints(ctx, plan->order[k]);
        piece* q = &p->pieces[i];
        q->meshlet = m;
        q->palette = pooled;
        q->vertices = plan->vertex_count[m];
        q->triangles = plan->triangle_count[m];
        q->joint_count = (uint16_t)ctx->open_joint_count;
        memcpy(p->pool + pooled, ctx->open_joints, ctx->open_joint_count * sizeof(uint16_t));
        pooled += ctx->open_joint_count;
        sp_meshlet_reset_open(ctx);
    }
    p->piece_count = count;
}

/* Distinct joints of bin b's pieces other than skip, plus those of piece add that they lack
 * (skip, add: NO_PIECE for none). */
static uint32_t joints_with(packer* p, uint32_t b, uint32_t skip, uint32_t add)
{
    if (++p->stamp == 0) { /* wrapped: clear the marks so that no old stamp matches */
        memset(p->mark, 0, p->ctx->joint_end * sizeof(uint32_t));
        p->stamp = 1;
    }
    uint32_t count = 0, stamp = p->stamp;
    for (uint32_t i = p->bins[b].first; i != NO_PIECE; i = p->pieces[i].next) {
        if (i == skip)
            continue;
        const uint16_t* joints = p->pool + p->pieces[i].palette;
        for (uint32_t k = 0; k < p->pieces[i].joint_count; ++k)
            if (p->mark[joints[k]] != stamp) {
                p->mark[joints[k]] = stamp;
                ++count;
            }
    }
    if (add != NO_PIECE) {
        const uint16_t* joints = p->pool + p->pieces[add].palette;
        for (uint32_t k = 0; k < p->pieces[add].joint_count; ++k)
            count += p->mark[joints[k]] != stamp;
    }
    return count;
}

/* Whether bin b can hold `vertices` / `triangles` more (after giving up `less` of its own). */
static int bin_has_room(const packer* p, uint32_t b, const piece* more, const piece* less)
{
    const pack_bin* bin = &p->bins[b];
    uint32_t vertices = bin->vertices + more->vertices - (less ? less->vertices : 0);
    uint32_t triangles = bin->triangles + more->triangles - (less ? less->triangles : 0);
    return vertices <= p->ctx->options.max_vertices && triangles <= p->ctx->options.max_triangles;
}

static void bin_insert(packer* p, uint32_t b, uint32_t i, uint32_t joints)
{
    piece* q = &p->pieces[i];
    q->bin = b;
    q->next = p->bins[b].first;
    p->bins[b].first = i;
    p->bins[b].vertices += q->vertices;
    p->bins[b].triangles += q->triangles;
    p->bins[b].joints = joints;
}

static void bin_remove(packer* p, uint32_t i, uint32_t joints)
{
    piece* q = &p->pieces[i];
    pack_bin* bin = &p->bins[q->bin];
    uint32_t* link = &bin->first;
    while (*link != i)
        link = &p->pieces[*link].next;
    *link = q->next;
    bin->vertices -= q->vertices;
    bin->triangles -= q->triangles;
    bin->joints = joints;
}

/* Greedy packing (step 1); with joints_first a piece never goes into a bin it adds a joint to.
 * Returns the palette sum; p->bin_count is the number of bins. */
static size_t pack_greedy(packer* p, int joints_first)
{
    const sp_meshlet_options* o = &p->ctx->options;
    uint32_t open[PACK_BINS], open_count = 0;
    size_t entries = 0;
    p->bin_count = 0;
    for (uint32_t i = 0; i < p->piece_count; ++i) {
        const piece* q = &p->pieces[i];
        uint32_t best = NO_PIECE, best_gain = 0, best_joints = 0;
        for (uint32_t k = 0; k < open_count; ++k) {
            uint32_t b = open[k];
            if (!bin_has_room(p, b, q, NULL))
                continue;
            uint32_t joints = joints_with(p, b, NO_PIECE, i), gain = joints - p->bins[b].joints;
            if (joints > o->max_joints || (joints_first && gain > 0))
                continue;
            if (best == NO_PIECE || gain < best_gain ||
                (gain == best_gain && p->bins[b].vertices > p->bins[open[best]].vertices)) {
                best = k;
                best_gain = gain;
                best_joints = joints;
            }
        }
        if (best == NO_PIECE) { /* a new bin, in a free open slot or in place of the fullest */
            if (open_count == PACK_BINS) {
                best = 0;
                for (uint32_t k = 1; k < open_count; ++k)
                    if (p->bins[open[k]].vertices > p->bins[open[best]].vertices)
                        best = k;
            } else
                best = open_count++;
            pack_bin fresh = {NO_PIECE, 0, 0, 0};
            p->bins[p->bin_count] = fresh;
            open[best] = p->bin_count++;
            best_gain = best_joints = q->joint_count;
        }
        uint32_t b = open[best];
        bin_insert(p, b, i, best_joints);
        entries += best_gain;
        if (!sp_meshlet_triangle_room(o, p->bins[b].vertices, p->bins[b].triangles))
            open[best] = open[--open_count]; /* full: no piece fits any more */
    }
    return entries;
}

/* Step 2 for piece i: the best move to another bin or swap with a piece of another bin, if it
 * lowers the palette sum; returns 1 if it changed the packing. */
static int improve_piece(packer* p, uint32_t i)
{
    const sp_meshlet_options* o = &p->ctx->options;
    uint32_t a = p->pieces[i].bin, without = joints_with(p, a, i, NO_PIECE);
    int best_delta = 0;
    uint32_t best_bin = NO_PIECE, best_other = NO_PIECE, best_a = 0, best_b = 0;
    for (uint32_t b = 0; b < p->bin_count; ++b) {
        if (b == a || p->bins[b].first == NO_PIECE)
            continue;
        uint32_t before = p->bins[a].joints + p->bins[b].joints;
        if (bin_has_room(p, b, &p->pieces[i], NULL)) { /* move i to b */
            uint32_t with = joints_with(p, b, NO_PIECE, i);
            int delta = (int)(without + with) - (int)before;
            if (with <= o->max_joints && delta < best_delta) {
                best_delta = delta;
                best_bin = b, best_other = NO_PIECE, best_a = without, best_b = with;
            }
        }
        for (uint32_t j = p->bins[b].first; j != NO_PIECE; j = p->pieces[j].next) { /* swap i and j */
            if (!bin_has_room(p, b, &p->pieces[i], &p->pieces[j]) || !bin_has_room(p, a, &p->pieces[j], &p->pieces[i]))
                continue;
            uint32_t new_a = joints_with(p, a, i, j), new_b = joints_with(p, b, j, i);
            int delta = (int)(new_a + new_b) - (int)before;
            if (new_a <= o->max_joints && new_b <= o->max_joints && delta < best_delta) {
                best_delta = delta;
                best_bin = b, best_other = j, best_a = new_a, best_b = new_b;
            }
        }
    }
    if (best_bin == NO_PIECE)
        return 0;
    bin_remove(p, i, best_a);
    if (best_other != NO_PIECE) {
        bin_remove(p, best_other, best_b);
        bin_insert(p, a, best_other, best_a);
    }
    bin_insert(p, best_bin, i, best_b);
    return 1;
}

static void pack_search(packer* p)
{
    for (int pass = 0; pass < SEARCH_PASSES; ++pass) {
        int changed = 0;
        for (uint32_t i = 0; i < p->piece_count; ++i)
            changed |= improve_piece(p, i);
        if (!changed)
            break;
    }
}

/* Writes the bins into the plan: each bin's pieces join the group of its first piece. */
static void apply_bins(const packer* p, sp_meshlet_plan* plan)
{
    for (uint32_t b = 0; b < p->bin_count; ++b) {
        uint32_t first = p->bins[b].first;
        if (first == NO_PIECE)
            continue;
        uint32_t head = p->pieces[first].meshlet;
        for (uint32_t i = p->pieces[first].next; i != NO_PIECE; i = p->pieces[i].next)
            sp_meshlet_plan_append(plan, head, p->pieces[i].meshlet);
        plan->vertex_count[head] = (uint16_t)p->bins[b].vertices;
    }
}

void sp_meshlet_plan_pack(sp_meshlet_context* ctx, sp_meshlet_plan* plan, unsigned char* scratch)
{
    packer p;
    p.ctx = ctx;
    uint64_t* keys = plan->keys; /* the merge step's sort keys, free until then */
    p.pieces = sp_meshlet_carve(&scratch, plan->count * sizeof(piece));
    p.pool = sp_meshlet_carve(&scratch, ctx->triangle_count * SP_MESHLET_TRIANGLE_JOINTS * sizeof(uint16_t));
    p.bins = sp_meshlet_carve(&scratch, plan->count * sizeof(pack_bin));
    p.mark = sp_meshlet_carve(&scratch, ctx->joint_end * sizeof(uint32_t));
    memset(p.mark, 0, ctx->joint_end * sizeof(uint32_t));
    p.stamp = 0;
    collect_pieces(&p, ctx, plan, keys);
    if (p.piece_count < 2)
        return;
    size_t joints_first = pack_greedy(&p, 1);
    uint32_t joints_first_bins = p.bin_count;
    size_t count_first = pack_greedy(&p, 0); /* last: kept on ties, then with no rerun */
    if (joints_first_bins < p.bin_count || (joints_first_bins == p.bin_count && joints_first < count_first))
        pack_greedy(&p, 1); /* the joints-first run again: it is the one kept */
    if (p.piece_count <= SEARCH_PIECES)
        pack_search(&p);
    apply_bins(&p, plan);
}
