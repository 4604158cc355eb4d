/*
 * fuzz_validate.c - libFuzzer target for sp_validate_packed, the library's one reader entry
 * point (input layout: validate_input.h; seeds for every method, K and mode from
 * make_validate_seeds.c). Besides "no crash, leak or sanitizer report" it checks what a
 * passing primitive promises: weighted joints below jointCount and distinct, weights finite,
 * non-negative and summing to 1; sp_decompress_skin agrees bit for bit; and the batch decoders
 * at every instruction-set cap (scalar, AVX2, AVX-512, as the CPU has them) give the same
 * weights. A failing one must come with a non-empty message.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../native/src/codec_internal.h"
#include "validate_input.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

/* Copies the next count * width bytes into a fresh, aligned buffer; NULL when data runs out. */
static void* take(const uint8_t** at, const uint8_t* end, size_t count, size_t width)
{
    size_t bytes = count * width;
    if ((size_t)(end - *at) < bytes) return NULL;
    void* copy = malloc(bytes ? bytes : 1);
    if (copy) memcpy(copy, *at, bytes);
    *at += bytes;
    return copy;
}

static void check_decoded(const sp_packed_primitive* prim, const sp_validation* report, const uint16_t* joints,
                          const float* weights)
{
    uint32_t k = report->codec.influences;
    for (size_t v = 0; v < prim->vertex_count; ++v) {
        double sum = 0;
        for (uint32_t s = 0; s < k; ++s) {
            float w = weights[v * k + s];
            if (!(w >= 0 && w <= 1)) abort();
            sum += w;
            if (w > 0 && joints[v * k + s] >= prim->params.joint_count) abort();
            for (uint32_t t = s + 1; t < k; ++t)
                if (w > 0 && weights[v * k + t] > 0 && joints[v * k + s] == joints[v * k + t]) abort();
        }
        if (fabs(sum - 1.0) > 1e-5) abort();
    }
}

/* The other decoders must agree with the validator on every vertex it accepted. */
static void check_other_decoders(const sp_packed_primitive* prim, const sp_validation* report, const uint16_t* joints,
                                 const float* weights)
{
    const sp_codec* codec = &report->codec;
    size_t n = prim->vertex_count, k = codec->influences;
    uint16_t* other_joints = malloc(n * k * sizeof(uint16_t));
    float* other_weights = malloc(n * k * sizeof(float));
    uint32_t* tuples = malloc(n * sizeof(uint32_t));
    uint64_t* codes = malloc(n * sizeof(uint64_t));
    if (!other_joints || !other_weights || !tuples || !codes) abort();
    if (sp_decompress_skin(codec, prim->words, n, (uint32_t)prim->params.tuple_bits, prim->lut, prim->lut_size,
                           (size_t)prim->params.joint_count, other_joints, other_weights, NULL) != SP_OK)
        abort();
    if (memcmp(other_joints, joints, n * k * sizeof(uint16_t)) || memcmp(other_weights, weights, n * k * sizeof(float)))
        abort();
    if (sp_unpack_vertices(prim->words, n, (uint32_t)prim->params.tuple_bits, codec->bits, tuples, codes, NULL) != SP_OK)
        abort();
    for (int isa = SP_ISA_SCALAR; isa <= SP_ISA_AVX512; ++isa) {
        if (sp_decode_weights_batch_isa(codec, codes, n, other_weights, NULL, (sp_isa)isa) != SP_OK) abort();
        if (memcmp(other_weights, weights, n * k * sizeof(float))) abort();
    }
    free(other_joints);
    free(other_weights);
    free(tuples);
    free(codes);
}

static sp_packed_meshlets* take_meshlets(const fuzz_header* h, const uint8_t** at, const uint8_t* end)
{
    sp_packed_meshlets* ml = calloc(1, sizeof(*ml));
    if (!ml) return NULL;
    size_t k = h->influences < 4 ? h->influences : 4;
    ml->meshlet_count = h->meshlet_count;
    ml->offsets = take(at, end, 4 * (size_t)h->meshlet_count, 4);
    uint16_t* counts16 = take(at, end, 4 * (size_t)h->meshlet_count, 2);
    ml->vertex_entries = h->vertex_entries;
    ml->vertices = take(at, end, h->vertex_entries, 4);
    ml->vertex_tuples = take(at, end, h->vertex_entries, 1);
    ml->triangle_bytes = h->triangle_bytes;
    ml->triangles = take(at, end, h->triangle_bytes, 1);
    ml->joint_entries = h->joint_entries;
    ml->joints = take(at, end, h->joint_entries, 2);
    ml->tuple_count = h->tuple_count;
    ml->tuples = take(at, end, (size_t)h->tuple_count * k, 1);
    uint32_t* counts = counts16 ? malloc(4 * (size_t)h->meshlet_count * 4 + 4) : NULL;
    for (size_t i = 0; counts && i < 4 * (size_t)h->meshlet_count; ++i) counts[i] = counts16[i];
    free(counts16);
    ml->counts = counts;
    ml->max_vertices = h->max_vertices, ml->max_triangles = h->max_triangles, ml->max_joints = h->max_joints;
    return ml;
}

static void free_meshlets(sp_packed_meshlets* ml)
{
    if (!ml) return;
    free((void*)ml->offsets), free((void*)ml->counts), free((void*)ml->vertices), free((void*)ml->vertex_tuples);
    free((void*)ml->triangles), free((void*)ml->joints), free((void*)ml->tuples), free(ml);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    fuzz_header h;
    if (size < sizeof(h)) return 0;
    memcpy(&h, data, sizeof(h));
    const uint8_t *at = data + sizeof(h), *end = data + size;
    sp_packed_primitive prim;
    memset(&prim, 0, sizeof(prim));
    sp_packed_params* p = &prim.params;
    p->method = h.method, p->influences = h.influences, p->joint_count = h.joint_count;
    p->weight_bits = h.weight_bits, p->tuple_bits = h.tuple_bits, p->n = h.n;
    memcpy(p->axis_samples, h.axes, sizeof(h.axes));
    p->axis_sample_count = h.axis_count;
    p->has_max_error = (h.flags & FUZZ_MAX_ERROR) != 0;
    p->max_error = h.max_error_milli / 1000.0;
    prim.vertex_count = h.vertex_count;
    prim.primitive_vertex_count = h.vertex_count + ((h.flags & FUZZ_COUNT_MISMATCH) != 0);
    prim.words_per_vertex = h.words_per_vertex;
    prim.lut_size = h.lut_size, prim.lut_components = h.lut_components, prim.lut_component_bytes = h.lut_component_bytes;
    prim.skin_joint_count = h.skin_joint_count;
    uint32_t* words = take(&at, end, (size_t)h.vertex_count * h.words_per_vertex, 4);
    uint16_t* lut = take(&at, end, (size_t)h.lut_size * h.lut_components, 2);
    sp_packed_meshlets* ml = (h.flags & FUZZ_MESHLETS) ? take_meshlets(&h, &at, end) : NULL;
    prim.words = words, prim.lut = lut, prim.meshlets = ml;
    int complete = words && lut && (!(h.flags & FUZZ_MESHLETS) || (ml && ml->offsets && ml->counts && ml->vertices &&
                                                                   ml->vertex_tuples && ml->triangles && ml->joints &&
                                                                   ml->tuples));
    if (complete) {
        size_t k = h.influences <= 4 ? h.influences : 4;
        uint16_t* joints = malloc((size_t)h.vertex_count * k * sizeof(uint16_t) + 2);
        float* weights = malloc((size_t)h.vertex_count * k * sizeof(float) + 4);
        sp_validation report;
        sp_result r = sp_validate_packed(&prim, joints, weights, &report);
        char message[256];
        size_t length = sp_format_validation(&report, message, sizeof(message));
        if (r != report.result || length == 0 || strlen(message) == 0) abort();
        if (r == SP_OK) {
            check_decoded(&prim, &report, joints, weights);
            check_other_decoders(&prim, &report, joints, weights);
        }
        free(joints);
        free(weights);
    }
    free(words);
    free(lut);
    free_meshlets(ml);
    return 0;
}
