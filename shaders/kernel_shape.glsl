// The specialization constants every search kernel is built with: the
// workgroup size, the database's shape and the best pairs kept per query.
// The C++ side is runtime/vulkan/src/kernel_shape.hpp (SpecId,
// shape_spec()); change both together. Kernel-specific constants (the scan's
// query tile T, the merge's ADD_CONTINUING) stay in their kernels.
#ifndef MMVK_KERNEL_SHAPE_GLSL
#define MMVK_KERNEL_SHAPE_GLSL

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint DV = 1;        // padded dims / 4
layout(constant_id = 2) const uint DIMS = 1;      // real dims (<= 128)
layout(constant_id = 4) const uint K = 1;         // best pairs kept per query
layout(constant_id = 5) const uint CHANNELS = 1;  // non-empty channels
// Bit d set: dimension d is the last of its channel.
layout(constant_id = 6) const uint END_MASK_0 = 0u;
layout(constant_id = 7) const uint END_MASK_1 = 0u;
layout(constant_id = 8) const uint END_MASK_2 = 0u;
layout(constant_id = 9) const uint END_MASK_3 = 0u;
// 32-bit words of the tag masks that any frame uses: 0 (no frame has a tag),
// 1 (only tags 0-31) or 2. The scans test only those words.
layout(constant_id = 12) const uint TAG_WORDS = 2;
// 1: every frame's cost multiplier is 1 and its bias 0 (or -0), so a row's
// cost is its weighted sum, bit for bit (1 x t + 0 is t for every t the
// sum can be: never -0.0, and NaN stays NaN).
layout(constant_id = 13) const uint UNIT_COST_TERMS = 0;

#endif
