/*
 * vk_context.h - the minimal headless Vulkan plumbing shared by the shader harness and the GPU
 * benchmark: one device and queue, buffers, the skinpack descriptor set (bindings of
 * shaders/skinpack_gpu_layout.h), compute and graphics pipelines, one-shot command buffers,
 * the barriers and attachments of a render pass.
 * Every failure prints what failed and exits(1): a test that cannot reach Vulkan fails.
 */
#ifndef SKINPACK_VK_CONTEXT_H
#define SKINPACK_VK_CONTEXT_H

#include <stddef.h>
#include <stdint.h>
#include <vulkan/vulkan.h>

#include "skinpack_gpu_layout.h"

#define VKX_CHECK(call)                                                                             \
    do {                                                                                            \
        VkResult vkx_result_ = (call);                                                              \
        if (vkx_result_ != VK_SUCCESS) vkx_fail("%s:%d: %s returned %d", __FILE__, __LINE__, #call, \
                                                (int)vkx_result_);                                   \
    } while (0)

typedef struct vkx_context {
    VkInstance instance;
    VkPhysicalDevice physical_device;
    VkPhysicalDeviceProperties properties;
    VkPhysicalDeviceMemoryProperties memory;
    VkDevice device;
    uint32_t queue_family;
    VkQueue queue;
    VkCommandPool command_pool;
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout pipeline_layout;
    VkDescriptorPool descriptor_pool;
    int has_mesh_shader;         /* VK_EXT_mesh_shader enabled */
    PFN_vkCmdDrawMeshTasksEXT draw_mesh_tasks;
} vkx_context;

typedef struct vkx_buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    VkDeviceSize size;
    void* mapped; /* non-NULL for host-visible buffers */
} vkx_buffer;

/* Prints the message and exits with status 1. */
void vkx_fail(const char* format, ...) __attribute__((noreturn, format(printf, 1, 2)));

/*
 * Creates the context on the first physical device (a discrete GPU if there is one).
 * want_mesh_shader: enable VK_EXT_mesh_shader when the device has it.
 * If the environment variable SKINPACK_EXPECT_DEVICE is set, the device name must contain it
 * (ctest sets it to "llvmpipe" so a run that silently picked another driver fails).
 */
void vkx_create(vkx_context* ctx, int want_mesh_shader);
void vkx_destroy(vkx_context* ctx);

/* host_visible: mapped, coherent memory (readback, small uploads); else device-local memory,
 * filled through vkx_upload (a staging copy). Size is rounded up to 16 bytes, never 0. */
vkx_buffer vkx_buffer_create(vkx_context* ctx, VkDeviceSize size, VkBufferUsageFlags usage, int host_visible);
void vkx_buffer_destroy(vkx_context* ctx, vkx_buffer* buffer);
/* A device-local storage buffer holding a copy of data. */
vkx_buffer vkx_upload(vkx_context* ctx, const void* data, size_t size, VkBufferUsageFlags usage);

/* A host-visible buffer holding a copy of data (a uniform block the tests write once). */
vkx_buffer vkx_host_buffer(vkx_context* ctx, const void* data, size_t size, VkBufferUsageFlags usage);
/* A host-visible output buffer filled with 0xcd bytes, so that whatever a shader fails to write
 * cannot pass a check. */
vkx_buffer vkx_poisoned_buffer(vkx_context* ctx, VkDeviceSize size, VkBufferUsageFlags usage);

/* One descriptor set of the shared layout. buffers[b] for each binding b < SP_BINDING_COUNT;
 * NULL entries get a small dummy buffer. Binding 0 is a uniform buffer, the rest storage. */
VkDescriptorSet vkx_descriptor_set(vkx_context* ctx, vkx_buffer* const buffers[SP_BINDING_COUNT], vkx_buffer* dummy);

/* SPIR-V from a file next to the executable's shader directory (SKINPACK_SHADER_DIR). */
VkShaderModule vkx_shader(vkx_context* ctx, const char* file_name);
/* Specialisation constants 0..3 of the skinning shaders (skin_common.glsl): vertex format,
 * codec method, K, decoder (SP_SPEC_RUNTIME: read from the codec block). decode.comp has none. */
typedef struct vkx_specialization {
    uint32_t vertex_format, method, influences, decoder;
} vkx_specialization;

/* Compute pipeline. */
VkPipeline vkx_compute_pipeline(vkx_context* ctx, const char* shader_file, const vkx_specialization* spec);
/* Graphics pipeline with dynamic rendering: vertex (or mesh) shader + skin.frag, depth test,
 * back faces culled (counter-clockwise front faces). mesh: first_stage is a mesh shader. */
VkPipeline vkx_graphics_pipeline(vkx_context* ctx, const char* first_stage_file, int mesh, const vkx_specialization* spec,
                                 VkFormat color_format, VkFormat depth_format);

VkCommandBuffer vkx_begin(vkx_context* ctx);
/* Ends, submits, waits for idle and frees the command buffer. */
void vkx_submit_and_wait(vkx_context* ctx, VkCommandBuffer cmd);

/* One compute dispatch of groups_x x groups_y workgroups with the set and push constants, made
 * visible to the host before it returns (the tests read the output buffers right after). */
void vkx_dispatch_and_wait(vkx_context* ctx, VkPipeline pipeline, VkDescriptorSet set, const void* push,
                           uint32_t push_size, uint32_t groups_x, uint32_t groups_y);

/* A device-local 2D image with its view (colour or depth attachment). */
typedef struct vkx_image {
    VkImage image;
    VkDeviceMemory memory;
    VkImageView view;
} vkx_image;
vkx_image vkx_image_create(vkx_context* ctx, uint32_t width, uint32_t height, VkFormat format, VkImageUsageFlags usage,
                           VkImageAspectFlags aspect);
void vkx_image_destroy(vkx_context* ctx, vkx_image* image);

/* vkCmdPipelineBarrier with one global memory barrier. */
void vkx_cmd_memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkPipelineStageFlags dst_stage,
                            VkAccessFlags src_access, VkAccessFlags dst_access);
/* A layout transition of the image's one mip level and layer, no queue family transfer. */
VkImageMemoryBarrier vkx_image_barrier(const vkx_image* image, VkImageAspectFlags aspect, VkAccessFlags src_access,
                                       VkAccessFlags dst_access, VkImageLayout old_layout, VkImageLayout new_layout);
/* An attachment of dynamic rendering in layout, cleared to clear on load. */
VkRenderingAttachmentInfo vkx_cleared_attachment(const vkx_image* image, VkImageLayout layout, VkAttachmentStoreOp store,
                                                 VkClearValue clear);

#endif
