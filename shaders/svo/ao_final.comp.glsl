#version 450
// svo.shading=ao: the final image is the ambient occlusion (grey; black where there is no
// surface), upsampled nearest from the traced resolution.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D u_ambientOcclusion;
layout(binding = 1) uniform sampler2D u_position;
layout(rgba8, binding = 0) uniform writeonly image2D u_final;
void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = textureSize(u_position, 0);
  if (px.x >= size.x || px.y >= size.y) return;
  ivec2 low = textureSize(u_ambientOcclusion, 0);
  ivec2 q = min(px * low / size, low - 1);
  float ao = texelFetch(u_position, px, 0).w == 0.0 ? 0.0 : texelFetch(u_ambientOcclusion, q, 0).r;
  imageStore(u_final, px, vec4(vec3(ao), 1.0));
}
