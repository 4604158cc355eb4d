/* vk_context.c - see vk_context.h. Plain Vulkan 1.3, no window system, no validation layers. */
#include "vk_context.h"

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef SKINPACK_SHADER_DIR
#error "SKINPACK_SHADER_DIR must name the folder with the compiled .spv files"
#endif

void vkx_fail(const char* format, ...)
{
    va_list args;
    va_start(args, format);
    fprintf(stderr, "FAIL: ");
    vfprintf(stderr, format, args);
    fprintf(stderr, "\n");
    va_end(args);
    exit(1);
}

static int has_extension(VkPhysicalDevice device, const char* name)
{
    uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(device, NULL, &count, NULL);
    VkExtensionProperties* extensions = calloc(count ? count : 1, sizeof(*extensions));
    vkEnumerateDeviceExtensionProperties(device, NULL, &count, extensions);
    int found = 0;
    for (uint32_t i = 0; i < count && !found; ++i) found = strcmp(extensions[i].extensionName, name) == 0;
    free(extensions);
    return found;
}

static void create_descriptor_layouts(vkx_context* ctx)
{
    VkDescriptorSetLayoutBinding bindings[SP_BINDING_COUNT];
    for (uint32_t b = 0; b < SP_BINDING_COUNT; ++b) {
        bindings[b] = (VkDescriptorSetLayoutBinding){
            .binding = b,
            .descriptorType = b == SP_BINDING_CODEC ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
            .descriptorCount = 1,
            .stageFlags = VK_SHADER_STAGE_ALL,
        };
    }
    VkDescriptorSetLayoutCreateInfo set_info = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
        .bindingCount = SP_BINDING_COUNT,
        .pBindings = bindings,
    };
    VKX_CHECK(vkCreateDescriptorSetLayout(ctx->device, &set_info, NULL, &ctx->set_layout));
    /* 128 bytes: the minimum every device guarantees; skin_common.glsl's block fits. */
    VkPushConstantRange push = {.stageFlags = VK_SHADER_STAGE_ALL, .offset = 0, .size = 128};
    VkPipelineLayoutCreateInfo layout_info = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
        .setLayoutCount = 1,
        .pSetLayouts = &ctx->set_layout,
        .pushConstantRangeCount = 1,
        .pPushConstantRanges = &push,
    };
    VKX_CHECK(vkCreatePipelineLayout(ctx->device, &layout_info, NULL, &ctx->pipeline_layout));
    VkDescriptorPoolSize sizes[2] = {
        {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 256},
        {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 256 * SP_BINDING_COUNT},
    };
    VkDescriptorPoolCreateInfo pool_info = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO,
        .maxSets = 256,
        .poolSizeCount = 2,
        .pPoolSizes = sizes,
    };
    VKX_CHECK(vkCreateDescriptorPool(ctx->device, &pool_info, NULL, &ctx->descriptor_pool));
}

static void create_instance(vkx_context* ctx)
{
    VkApplicationInfo app = {
        .sType = VK_STRUCTURE_TYPE_APPLICATION_INFO,
        .pApplicationName = "skinpack",
        .apiVersion = VK_API_VERSION_1_3,
    };
    VkInstanceCreateInfo instance_info = {.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, .pApplicationInfo = &app};
    VkResult result = vkCreateInstance(&instance_info, NULL, &ctx->instance);
    if (result != VK_SUCCESS)
        vkx_fail("vkCreateInstance returned %d: no Vulkan driver (install mesa-vulkan-drivers for lavapipe)", (int)result);
}

/* The first physical device, or the first discrete GPU if there is one; fails when it is not
 * the one SKINPACK_EXPECT_DEVICE names or has no Vulkan 1.3. */
static void pick_physical_device(vkx_context* ctx)
{
    uint32_t count = 0;
    vkEnumeratePhysicalDevices(ctx->instance, &count, NULL);
    if (count == 0) vkx_fail("no Vulkan physical device (VK_ICD_FILENAMES=%s)", getenv("VK_ICD_FILENAMES") ? getenv("VK_ICD_FILENAMES") : "unset");
    VkPhysicalDevice devices[16];
    if (count > 16) count = 16;
    vkEnumeratePhysicalDevices(ctx->instance, &count, devices);
    ctx->physical_device = devices[0];
    for (uint32_t i = 0; i < count; ++i) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(devices[i], &p);
        if (p.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU) {
            ctx->physical_device = devices[i];
            break;
        }
    }
    vkGetPhysicalDeviceProperties(ctx->physical_device, &ctx->properties);
    vkGetPhysicalDeviceMemoryProperties(ctx->physical_device, &ctx->memory);
    const char* expected = getenv("SKINPACK_EXPECT_DEVICE");
    if (expected && *expected && !strstr(ctx->properties.deviceName, expected))
        vkx_fail("device is \"%s\", SKINPACK_EXPECT_DEVICE wants \"%s\"", ctx->properties.deviceName, expected);
    if (VK_API_VERSION_MINOR(ctx->properties.apiVersion) < 3 && VK_API_VERSION_MAJOR(ctx->properties.apiVersion) == 1)
        vkx_fail("device \"%s\" has Vulkan 1.%u; 1.3 is needed (dynamic rendering)", ctx->properties.deviceName,
                 VK_API_VERSION_MINOR(ctx->properties.apiVersion));
}

/* One queue does everything, and the benchmark times it: graphics + compute + timestamps. */
static void pick_queue_family(vkx_context* ctx)
{
    uint32_t family_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(ctx->physical_device, &family_count, NULL);
    VkQueueFamilyProperties families[16];
    if (family_count > 16) family_count = 16;
    vkGetPhysicalDeviceQueueFamilyProperties(ctx->physical_device, &family_count, families);
    ctx->queue_family = UINT32_MAX;
    for (uint32_t i = 0; i < family_count; ++i) {
        VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
        if ((families[i].queueFlags & need) == need && families[i].timestampValidBits > 0) {
            ctx->queue_family = i;
            break;
        }
    }
    if (ctx->queue_family == UINT32_MAX) vkx_fail("no graphics+compute queue with timestamps");
}

/* The device with dynamic rendering, and VK_EXT_mesh_shader when wanted and there. */
static void create_device(vkx_context* ctx, int want_mesh_shader)
{
    ctx->has_mesh_shader = want_mesh_shader && has_extension(ctx->physical_device, VK_EXT_MESH_SHADER_EXTENSION_NAME);
    VkPhysicalDeviceMeshShaderFeaturesEXT mesh_features = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT,
        .meshShader = VK_TRUE,
    };
    VkPhysicalDeviceVulkan13Features features13 = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES,
        .pNext = ctx->has_mesh_shader ? &mesh_features : NULL,
        .dynamicRendering = VK_TRUE,
    };
    VkPhysicalDeviceFeatures2 features = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &features13};
    float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info = {
        .sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO,
        .queueFamilyIndex = ctx->queue_family,
        .queueCount = 1,
        .pQueuePriorities = &priority,
    };
    const char* extensions[] = {VK_EXT_MESH_SHADER_EXTENSION_NAME};
    VkDeviceCreateInfo device_info = {
        .sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO,
        .pNext = &features,
        .queueCreateInfoCount = 1,
        .pQueueCreateInfos = &queue_info,
        .enabledExtensionCount = ctx->has_mesh_shader ? 1u : 0u,
        .ppEnabledExtensionNames = extensions,
    };
    VKX_CHECK(vkCreateDevice(ctx->physical_device, &device_info, NULL, &ctx->device));
    vkGetDeviceQueue(ctx->device, ctx->queue_family, 0, &ctx->queue);
    if (ctx->has_mesh_shader)
        ctx->draw_mesh_tasks = (PFN_vkCmdDrawMeshTasksEXT)vkGetDeviceProcAddr(ctx->device, "vkCmdDrawMeshTasksEXT");
}

void vkx_create(vkx_context* ctx, int want_mesh_shader)
{
    memset(ctx, 0, sizeof(*ctx));
    create_instance(ctx);
    pick_physical_device(ctx);
    pick_queue_family(ctx);
    create_device(ctx, want_mesh_shader);
    VkCommandPoolCreateInfo pool_info = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
        .flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT,
        .queueFamilyIndex = ctx->queue_family,
    };
    VKX_CHECK(vkCreateCommandPool(ctx->device, &pool_info, NULL, &ctx->command_pool));
    create_descriptor_layouts(ctx);
}

void vkx_destroy(vkx_context* ctx)
{
    vkDeviceWaitIdle(ctx->device);
    vkDestroyDescriptorPool(ctx->device, ctx->descriptor_pool, NULL);
    vkDestroyPipelineLayout(ctx->device, ctx->pipeline_layout, NULL);
    vkDestroyDescriptorSetLayout(ctx->device, ctx->set_layout, NULL);
    vkDestroyCommandPool(ctx->device, ctx->command_pool, NULL);
    vkDestroyDevice(ctx->device, NULL);
    vkDestroyInstance(ctx->instance, NULL);
}

static uint32_t memory_type(vkx_context* ctx, uint32_t allowed, VkMemoryPropertyFlags want)
{
    for (uint32_t i = 0; i < ctx->memory.memoryTypeCount; ++i)
        if ((allowed & (1u << i)) && (ctx->memory.memoryTypes[i].propertyFlags & want) == want) return i;
    vkx_fail("no memory type with properties 0x%x", (unsigned)want);
}

static VkDeviceMemory allocate_memory(vkx_context* ctx, const VkMemoryRequirements* requirements, VkMemoryPropertyFlags want)
{
    VkMemoryAllocateInfo allocate = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO,
        .allocationSize = requirements->size,
        .memoryTypeIndex = memory_type(ctx, requirements->memoryTypeBits, want),
    };
    VkDeviceMemory memory;
    VKX_CHECK(vkAllocateMemory(ctx->device, &allocate, NULL, &memory));
    return memory;
}

vkx_buffer vkx_buffer_create(vkx_context* ctx, VkDeviceSize size, VkBufferUsageFlags usage, int host_visible)
{
    vkx_buffer buffer = {0};
    buffer.size = size ? (size + 15) & ~(VkDeviceSize)15 : 16;
    VkBufferCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO,
        .size = buffer.size,
        .usage = usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
    };
    VKX_CHECK(vkCreateBuffer(ctx->device, &info, NULL, &buffer.buffer));
    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(ctx->device, buffer.buffer, &requirements);
    VkMemoryPropertyFlags want = host_visible ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                              : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    buffer.memory = allocate_memory(ctx, &requirements, want);
    VKX_CHECK(vkBindBufferMemory(ctx->device, buffer.buffer, buffer.memory, 0));
    if (host_visible) VKX_CHECK(vkMapMemory(ctx->device, buffer.memory, 0, VK_WHOLE_SIZE, 0, &buffer.mapped));
    return buffer;
}

void vkx_buffer_destroy(vkx_context* ctx, vkx_buffer* buffer)
{
    if (buffer->mapped) vkUnmapMemory(ctx->device, buffer->memory);
    vkDestroyBuffer(ctx->device, buffer->buffer, NULL);
    vkFreeMemory(ctx->device, buffer->memory, NULL);
    memset(buffer, 0, sizeof(*buffer));
}

vkx_buffer vkx_upload(vkx_context* ctx, const void* data, size_t size, VkBufferUsageFlags usage)
{
    vkx_buffer staging = vkx_buffer_create(ctx, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, 1);
    memset(staging.mapped, 0, staging.size);
    if (size) memcpy(staging.mapped, data, size);
    vkx_buffer buffer = vkx_buffer_create(ctx, size, usage, 0);
    VkCommandBuffer cmd = vkx_begin(ctx);
    VkBufferCopy region = {.size = buffer.size};
    vkCmdCopyBuffer(cmd, staging.buffer, buffer.buffer, 1, &region);
    vkx_submit_and_wait(ctx, cmd);
    vkx_buffer_destroy(ctx, &staging);
    return buffer;
}

vkx_buffer vkx_host_buffer(vkx_context* ctx, const void* data, size_t size, VkBufferUsageFlags usage)
{
    vkx_buffer buffer = vkx_buffer_create(ctx, size, usage, 1);
    memcpy(buffer.mapped, data, size);
    return buffer;
}

vkx_buffer vkx_poisoned_buffer(vkx_context* ctx, VkDeviceSize size, VkBufferUsageFlags usage)
{
    vkx_buffer buffer = vkx_buffer_create(ctx, size, usage, 1);
    memset(buffer.mapped, 0xcd, buffer.size);
    return buffer;
}

VkDescriptorSet vkx_descriptor_set(vkx_context* ctx, vkx_buffer* const buffers[SP_BINDING_COUNT], vkx_buffer* dummy)
{
    VkDescriptorSetAllocateInfo allocate = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
        .descriptorPool = ctx->descriptor_pool,
        .descriptorSetCount = 1,
        .pSetLayouts = &ctx->set_layout,
    };
    VkDescriptorSet set;
    VKX_CHECK(vkAllocateDescriptorSets(ctx->device, &allocate, &set));
    VkDescriptorBufferInfo infos[SP_BINDING_COUNT];
    VkWriteDescriptorSet writes[SP_BINDING_COUNT];
    for (uint32_t b = 0; b < SP_BINDING_COUNT; ++b) {
        const vkx_buffer* buffer = buffers[b] ? buffers[b] : dummy;
        infos[b] = (VkDescriptorBufferInfo){.buffer = buffer->buffer, .offset = 0, .range = VK_WHOLE_SIZE};
        writes[b] = (VkWriteDescriptorSet){
            .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
            .dstSet = set,
            .dstBinding = b,
            .descriptorCount = 1,
            .descriptorType = b == SP_BINDING_CODEC ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
            .pBufferInfo = &infos[b],
        };
    }
    vkUpdateDescriptorSets(ctx->device, SP_BINDING_COUNT, writes, 0, NULL);
    return set;
}

VkShaderModule vkx_shader(vkx_context* ctx, const char* file_name)
{
    char path[1024];
    /* SKINPACK_SHADER_DIR in the environment: a staged copy run elsewhere (tests/bench/gpu_stage.sh) */
    const char* folder = getenv("SKINPACK_SHADER_DIR") ? getenv("SKINPACK_SHADER_DIR") : SKINPACK_SHADER_DIR;
    snprintf(path, sizeof(path), "%s/%s", folder, file_name);
    FILE* file = fopen(path, "rb");
    if (!file) vkx_fail("cannot open %s (build the skinpack_shaders target)", path);
    fseek(file, 0, SEEK_END);
    long size = ftell(file);
    fseek(file, 0, SEEK_SET);
    uint32_t* code = malloc((size_t)size);
    if (fread(code, 1, (size_t)size, file) != (size_t)size) vkx_fail("cannot read %s", path);
    fclose(file);
    VkShaderModuleCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
        .codeSize = (size_t)size,
        .pCode = code,
    };
    VkShaderModule module;
    VKX_CHECK(vkCreateShaderModule(ctx->device, &info, NULL, &module));
    free(code);
    return module;
}

static VkSpecializationInfo specialization_info(const vkx_specialization* spec)
{
    static const VkSpecializationMapEntry entries[4] = {
        {0, offsetof(vkx_specialization, vertex_format), sizeof(uint32_t)},
        {1, offsetof(vkx_specialization, method), sizeof(uint32_t)},
        {2, offsetof(vkx_specialization, influences), sizeof(uint32_t)},
        {3, offsetof(vkx_specialization, decoder), sizeof(uint32_t)},
    };
    return (VkSpecializationInfo){.mapEntryCount = 4, .pMapEntries = entries, .dataSize = sizeof(*spec), .pData = spec};
}

VkPipeline vkx_compute_pipeline(vkx_context* ctx, const char* shader_file, const vkx_specialization* spec)
{
    VkSpecializationInfo specialization = specialization_info(spec);
    VkComputePipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
        .stage = {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
            .stage = VK_SHADER_STAGE_COMPUTE_BIT,
            .module = vkx_shader(ctx, shader_file),
            .pName = "main",
            .pSpecializationInfo = &specialization,
        },
        .layout = ctx->pipeline_layout,
    };
    VkPipeline pipeline;
    VKX_CHECK(vkCreateComputePipelines(ctx->device, VK_NULL_HANDLE, 1, &info, NULL, &pipeline));
    vkDestroyShaderModule(ctx->device, info.stage.module, NULL);
    return pipeline;
}

/* The fixed-function state of vkx_graphics_pipeline, kept together because the create info
 * points into it. */
typedef struct graphics_state {
    VkPipelineVertexInputStateCreateInfo vertex_input;
    VkPipelineInputAssemblyStateCreateInfo assembly;
    VkPipelineViewportStateCreateInfo viewport;
    VkPipelineRasterizationStateCreateInfo raster;
    VkPipelineMultisampleStateCreateInfo multisample;
    VkPipelineDepthStencilStateCreateInfo depth;
    VkPipelineColorBlendAttachmentState blend_attachment;
    VkPipelineColorBlendStateCreateInfo blend;
    VkDynamicState dynamic_states[2];
    VkPipelineDynamicStateCreateInfo dynamic;
} graphics_state;

/* Triangle lists, dynamic viewport and scissor, back faces culled, depth test, no blending. */
static void graphics_state_init(graphics_state* s)
{
    s->vertex_input = (VkPipelineVertexInputStateCreateInfo){.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    s->assembly = (VkPipelineInputAssemblyStateCreateInfo){
        .sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
        .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST,
    };
    s->viewport = (VkPipelineViewportStateCreateInfo){
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO,
        .viewportCount = 1,
        .scissorCount = 1,
    };
    s->raster = (VkPipelineRasterizationStateCreateInfo){
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO,
        .polygonMode = VK_POLYGON_MODE_FILL,
        .cullMode = VK_CULL_MODE_BACK_BIT,
        .frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE,
        .lineWidth = 1.0f,
    };
    s->multisample = (VkPipelineMultisampleStateCreateInfo){
        .sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO,
        .rasterizationSamples = VK_SAMPLE_COUNT_1_BIT,
    };
    s->depth = (VkPipelineDepthStencilStateCreateInfo){
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
        .depthTestEnable = VK_TRUE,
        .depthWriteEnable = VK_TRUE,
        .depthCompareOp = VK_COMPARE_OP_LESS,
    };
    s->blend_attachment = (VkPipelineColorBlendAttachmentState){.colorWriteMask = 0xf};
    s->blend = (VkPipelineColorBlendStateCreateInfo){
        .sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
        .attachmentCount = 1,
        .pAttachments = &s->blend_attachment,
    };
    s->dynamic_states[0] = VK_DYNAMIC_STATE_VIEWPORT;
    s->dynamic_states[1] = VK_DYNAMIC_STATE_SCISSOR;
    s->dynamic = (VkPipelineDynamicStateCreateInfo){
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO,
        .dynamicStateCount = 2,
        .pDynamicStates = s->dynamic_states,
    };
}

VkPipeline vkx_graphics_pipeline(vkx_context* ctx, const char* first_stage_file, int mesh, const vkx_specialization* spec,
                                 VkFormat color_format, VkFormat depth_format)
{
    VkSpecializationInfo specialization = specialization_info(spec);
    VkPipelineShaderStageCreateInfo stages[2] = {
        {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
            .stage = mesh ? VK_SHADER_STAGE_MESH_BIT_EXT : VK_SHADER_STAGE_VERTEX_BIT,
            .module = vkx_shader(ctx, first_stage_file),
            .pName = "main",
            .pSpecializationInfo = &specialization,
        },
        {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
            .stage = VK_SHADER_STAGE_FRAGMENT_BIT,
            .module = vkx_shader(ctx, "skin.frag.spv"),
            .pName = "main",
        },
    };
    graphics_state state;
    graphics_state_init(&state);
    VkPipelineRenderingCreateInfo rendering = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO,
        .colorAttachmentCount = 1,
        .pColorAttachmentFormats = &color_format,
        .depthAttachmentFormat = depth_format,
    };
    /* A mesh shader makes its own primitives: no vertex input, no input assembly. */
    VkGraphicsPipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO,
        .pNext = &rendering,
        .stageCount = 2,
        .pStages = stages,
        .pVertexInputState = mesh ? NULL : &state.vertex_input,
        .pInputAssemblyState = mesh ? NULL : &state.assembly,
        .pViewportState = &state.viewport,
        .pRasterizationState = &state.raster,
        .pMultisampleState = &state.multisample,
        .pDepthStencilState = &state.depth,
        .pColorBlendState = &state.blend,
        .pDynamicState = &state.dynamic,
        .layout = ctx->pipeline_layout,
    };
    VkPipeline pipeline;
    VKX_CHECK(vkCreateGraphicsPipelines(ctx->device, VK_NULL_HANDLE, 1, &info, NULL, &pipeline));
    vkDestroyShaderModule(ctx->device, stages[0].module, NULL);
    vkDestroyShaderModule(ctx->device, stages[1].module, NULL);
    return pipeline;
}

VkCommandBuffer vkx_begin(vkx_context* ctx)
{
    VkCommandBufferAllocateInfo allocate = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = ctx->command_pool,
        .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = 1,
    };
    VkCommandBuffer cmd;
    VKX_CHECK(vkAllocateCommandBuffers(ctx->device, &allocate, &cmd));
    VkCommandBufferBeginInfo begin = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT,
    };
    VKX_CHECK(vkBeginCommandBuffer(cmd, &begin));
    return cmd;
}

void vkx_submit_and_wait(vkx_context* ctx, VkCommandBuffer cmd)
{
    VKX_CHECK(vkEndCommandBuffer(cmd));
    VkSubmitInfo submit = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO, .commandBufferCount = 1, .pCommandBuffers = &cmd};
    VKX_CHECK(vkQueueSubmit(ctx->queue, 1, &submit, VK_NULL_HANDLE));
    VKX_CHECK(vkQueueWaitIdle(ctx->queue));
    vkFreeCommandBuffers(ctx->device, ctx->command_pool, 1, &cmd);
}

void vkx_dispatch_and_wait(vkx_context* ctx, VkPipeline pipeline, VkDescriptorSet set, const void* push,
                           uint32_t push_size, uint32_t groups_x, uint32_t groups_y)
{
    VkCommandBuffer cmd = vkx_begin(ctx);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, ctx->pipeline_layout, 0, 1, &set, 0, NULL);
    vkCmdPushConstants(cmd, ctx->pipeline_layout, VK_SHADER_STAGE_ALL, 0, push_size, push);
    vkCmdDispatch(cmd, groups_x, groups_y, 1);
    vkx_cmd_memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                           VK_ACCESS_HOST_READ_BIT);
    vkx_submit_and_wait(ctx, cmd);
}

void vkx_cmd_memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkPipelineStageFlags dst_stage,
                            VkAccessFlags src_access, VkAccessFlags dst_access)
{
    VkMemoryBarrier barrier = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER, .srcAccessMask = src_access, .dstAccessMask = dst_access};
    vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 1, &barrier, 0, NULL, 0, NULL);
}

VkImageMemoryBarrier vkx_image_barrier(const vkx_image* image, VkImageAspectFlags aspect, VkAccessFlags src_access,
                                       VkAccessFlags dst_access, VkImageLayout old_layout, VkImageLayout new_layout)
{
    return (VkImageMemoryBarrier){
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER,
        .srcAccessMask = src_access,
        .dstAccessMask = dst_access,
        .oldLayout = old_layout,
        .newLayout = new_layout,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = image->image,
        .subresourceRange = {aspect, 0, 1, 0, 1},
    };
}

vkx_image vkx_image_create(vkx_context* ctx, uint32_t width, uint32_t height, VkFormat format, VkImageUsageFlags usage,
                           VkImageAspectFlags aspect)
{
    vkx_image image = {0};
    VkImageCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO,
        .imageType = VK_IMAGE_TYPE_2D,
        .format = format,
        .extent = {width, height, 1},
        .mipLevels = 1,
        .arrayLayers = 1,
        .samples = VK_SAMPLE_COUNT_1_BIT,
        .tiling = VK_IMAGE_TILING_OPTIMAL,
        .usage = usage,
    };
    VKX_CHECK(vkCreateImage(ctx->device, &info, NULL, &image.image));
    VkMemoryRequirements requirements;
    vkGetImageMemoryRequirements(ctx->device, image.image, &requirements);
    image.memory = allocate_memory(ctx, &requirements, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VKX_CHECK(vkBindImageMemory(ctx->device, image.image, image.memory, 0));
    VkImageViewCreateInfo view = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO,
        .image = image.image,
        .viewType = VK_IMAGE_VIEW_TYPE_2D,
        .format = format,
        .subresourceRange = {aspect, 0, 1, 0, 1},
    };
    VKX_CHECK(vkCreateImageView(ctx->device, &view, NULL, &image.view));
    return image;
}

void vkx_image_destroy(vkx_context* ctx, vkx_image* image)
{
    vkDestroyImageView(ctx->device, image->view, NULL);
    vkDestroyImage(ctx->device, image->image, NULL);
    vkFreeMemory(ctx->device, image->memory, NULL);
}

VkRenderingAttachmentInfo vkx_cleared_attachment(const vkx_image* image, VkImageLayout layout, VkAttachmentStoreOp store,
                                                 VkClearValue clear)
{
    return (VkRenderingAttachmentInfo){
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = image->view,
        .imageLayout = layout,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
        .storeOp = store,
        .clearValue = clear,
    };
}
