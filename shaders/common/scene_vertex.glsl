// Vertex inputs of the scene's vertex buffer (src/scene/gpu_scene.cpp).
#include "common/shared.h"
layout(location = VOXLAB_ATTR_POSITION) in vec3 a_position;
layout(location = VOXLAB_ATTR_NORMAL) in vec3 a_normal;
layout(location = VOXLAB_ATTR_UV) in vec2 a_uv;
