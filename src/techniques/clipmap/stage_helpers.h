// Helpers shared by the clipmap's stage files (layout.cpp defines them); not part of the
// technique's interface (stages.h).
#pragma once
#include <cstdint>
#include <vector>

#include "gpu/gl.h"
#include "graph/stage.h"
#include "techniques/clipmap/stages.h"

namespace voxlab::clipmap {

inline constexpr int kMaxLevels = 8;        // CLIPMAP_MAX_LEVELS in shaders/clipmap/clipmap.glsl
inline constexpr int kCountersPerLevel = 5; // cleared, pairs, resolved, filtered, guards
// The per-level counters, then one more: fixed-point light sums that wrapped past 2^32.
size_t countersBytes(int levels);
// The accumulators' uniforms of shaders/clipmap/clipmap.glsl (u_cellWords, u_accumulatorLevels,
// u_fixedScale, u_maxRadiance), for accumulators of 'accumulatorLevels' levels:
// 1 where the levels take turns (update), clipmap.levels where one pass fills them all.
void setAccumulatorUniforms(GLuint program, const ParamSet& params, int accumulatorLevels);
// One line on stderr and a statistic when fixed-point light sums overflowed (the count of wraps).
void reportOverflow(StageContext& ctx, const char* stage, uint32_t wraps);
size_t accumulatorBytes(const ParamSet& p, int accumulatorLevels);
// The uniforms every clipmap shader shares (shaders/clipmap/clipmap.glsl).
void setClipUniforms(GLuint program, const Layout& layout, const std::vector<Cell>& origins);
void dispatchBox(GLuint program, const Box& box);
inline constexpr GLbitfield kAllShaderWrites =
    GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
    GL_BUFFER_UPDATE_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT;

}  // namespace voxlab::clipmap
