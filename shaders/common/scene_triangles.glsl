// The scene's triangles read as buffers (compute voxelizers): GpuScene's interleaved vertex buffer
// (8 floats per vertex: position, normal, uv) and its index buffer (3 uints per triangle).
#include "common/shared.h"
layout(std430, binding = VOXLAB_BINDING_SCENE_VERTICES) readonly buffer SceneVertices { float sceneVertices[]; };
layout(std430, binding = VOXLAB_BINDING_SCENE_INDICES) readonly buffer SceneIndices { uint sceneIndices[]; };

uint sceneVertexIndex(uint triangle, int corner) { return sceneIndices[3u * triangle + uint(corner)]; }
vec3 scenePosition(uint v) { return vec3(sceneVertices[8u * v], sceneVertices[8u * v + 1u], sceneVertices[8u * v + 2u]); }
vec2 sceneUv(uint v) { return vec2(sceneVertices[8u * v + 6u], sceneVertices[8u * v + 7u]); }
vec3 sceneNormal(uint v) { return vec3(sceneVertices[8u * v + 3u], sceneVertices[8u * v + 4u], sceneVertices[8u * v + 5u]); }

// Dominant axis of a plane normal: 0 = x, 1 = y, 2 = z (ties as in common/voxelize.geom.glsl).
int dominantAxis(vec3 n) {
  vec3 an = abs(n);
  return (an.x >= an.y && an.x >= an.z) ? 0 : (an.y >= an.z ? 1 : 2);
}
