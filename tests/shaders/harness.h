/*
 * harness.h - what the parts of skinpack_shader_harness share: the Vulkan context, the mismatch
 * counter, and the tests that live in files of their own.
 */
#ifndef SKINPACK_HARNESS_H
#define SKINPACK_HARNESS_H

#include <stddef.h>

#include "sp_gpu.h"
#include "vk_context.h"

#define MAX_REPORTED_FAILURES 10

typedef struct harness {
    vkx_context ctx;
    VkPipeline decode_pipeline;
    vkx_buffer dummy;
    size_t checked;
    size_t failures;
    size_t unsorted_codes; /* codes libskinpack accepts whose weights are not descending */
} harness;

/* Counts a mismatch; prints the first MAX_REPORTED_FAILURES. */
void fail_check(harness* h, const char* format, ...) __attribute__((format(printf, 2, 3)));

/* Runs decode.comp over item_count items (shader_harness.c); returns malloc'ed records. */
SpDecodedRecord* gpu_decode(harness* h, const SpGpuCodec* codec, uint32_t mode, const uint32_t* words,
                            size_t word_count, size_t item_count, const void* lut, size_t lut_bytes, int force_wide);
/* A record's integer q_slot (x for Any) and its float weights. */
uint64_t record_q(const SpDecodedRecord* r, int slot);
const float* record_weights(const SpDecodedRecord* r);

/* conformance FILE (harness_conformance.c): every valid vector of the spec's weights.jsonl. */
void test_conformance(harness* h, const char* path);

/* meshshader FILE (harness_meshshader.c): skin.mesh's body through skin_meshlet_test.comp. */
void test_meshshader(harness* h, const char* path);

#endif
