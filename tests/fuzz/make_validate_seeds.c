/*
 * Writes the seed corpus of fuzz_validate (tests/fuzz/corpus/validate/): the fixture sheet of
 * packed_fixture.h (6 x 6 vertices) packed with every method, K = 1..4 and mode (32-bit words,
 * 64-bit words, small 12-bit words, 32-bit words with meshlets), in validate_input.h's layout.
 * Run by hand when the layout changes: build/tests/unit/make_validate_seeds tests/fuzz/corpus/validate
 */
#include <stdio.h>

#define FIXTURE_GRID 6
#include "packed_fixture.h"
#include "validate_input.h"

static void put(FILE* f, const void* data, size_t count, size_t width) { fwrite(data, width, count, f); }

static void write_seed(const char* dir, const char* name, const sp_packed_primitive* prim)
{
    char path[512];
    snprintf(path, sizeof(path), "%s/%s.bin", dir, name);
    FILE* f = fopen(path, "wb");
    if (!f) return;
    const sp_packed_params* p = &prim->params;
    const sp_packed_meshlets* ml = prim->meshlets;
    fuzz_header h;
    memset(&h, 0, sizeof(h));
    h.method = (uint8_t)p->method, h.influences = (uint8_t)p->influences, h.weight_bits = (uint8_t)p->weight_bits;
    h.tuple_bits = (uint8_t)p->tuple_bits, h.words_per_vertex = (uint8_t)prim->words_per_vertex;
    h.lut_components = (uint8_t)prim->lut_components, h.lut_component_bytes = (uint8_t)prim->lut_component_bytes;
    h.axis_count = (uint8_t)p->axis_sample_count, h.flags = (ml ? FUZZ_MESHLETS : 0) | FUZZ_MAX_ERROR;
    h.max_error_milli = 1, h.joint_count = (uint16_t)p->joint_count, h.skin_joint_count = (uint16_t)prim->skin_joint_count;
    h.vertex_count = (uint16_t)prim->vertex_count, h.lut_size = (uint16_t)prim->lut_size, h.n = p->n;
    memcpy(h.axes, p->axis_samples, sizeof(h.axes));
    if (ml) {
        h.max_vertices = (uint8_t)ml->max_vertices, h.max_triangles = (uint16_t)ml->max_triangles;
        h.max_joints = (uint8_t)ml->max_joints, h.meshlet_count = (uint16_t)ml->meshlet_count;
        h.vertex_entries = (uint16_t)ml->vertex_entries, h.triangle_bytes = (uint16_t)ml->triangle_bytes;
        h.joint_entries = (uint16_t)ml->joint_entries, h.tuple_count = (uint16_t)ml->tuple_count;
    }
    put(f, &h, 1, sizeof(h));
    put(f, prim->words, prim->vertex_count * prim->words_per_vertex, 4);
    put(f, prim->lut, prim->lut_size * prim->lut_components, 2);
    if (ml) {
        put(f, ml->offsets, 4 * ml->meshlet_count, 4);
        for (size_t i = 0; i < 4 * ml->meshlet_count; ++i) {
            uint16_t c = (uint16_t)ml->counts[i];
            put(f, &c, 1, 2);
        }
        put(f, ml->vertices, ml->vertex_entries, 4);
        put(f, ml->vertex_tuples, ml->vertex_entries, 1);
        put(f, ml->triangles, ml->triangle_bytes, 1);
        put(f, ml->joints, ml->joint_entries, 2);
        put(f, ml->tuples, ml->tuple_count * p->influences, 1);
    }
    fclose(f);
}

int main(int argc, char** argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: make_validate_seeds DIR\n");
        return 2;
    }
    static packed p;
    static meshlet_arrays arrays;
    static const struct { const char* name; uint32_t vertex_bits; int meshlets; } modes[] = {
        {"w32", 32, 0}, {"w64", 64, 0}, {"w12", 12, 0}, {"meshlets", 32, 1}};
    int written = 0;
    for (size_t k = 1; k <= 4; ++k) {
        make_mesh(k);
        for (int m = 0; m < SP_METHOD_COUNT; ++m)
            for (size_t mode = 0; mode < sizeof(modes) / sizeof(modes[0]); ++mode) {
                sp_compress_options o;
                sp_compress_options_default(&o);
                o.method = (sp_method)m;
                o.max_influences = (uint32_t)k;
                o.vertex_bits = modes[mode].vertex_bits;
                if (compress(&o, &p) != SP_OK || (modes[mode].meshlets && build_meshlets(&p, &arrays) != 0)) continue;
                p.prim.meshlets = modes[mode].meshlets ? &arrays.view : NULL;
                if (sp_validate_packed(&p.prim, NULL, NULL, NULL) != SP_OK) return 1;
                char name[64];
                snprintf(name, sizeof(name), "%s_k%zu_%s", sp_method_name((sp_method)m), k, modes[mode].name);
                write_seed(argv[1], name, &p.prim);
                ++written;
            }
    }
    printf("%d seeds\n", written);
    return written ? 0 : 1;
}
