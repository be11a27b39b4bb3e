// Cone tracing through a prefiltered (mipmapped) voxel volume of premultiplied radiance and
// opacity (Crassin et al. 2011). Along the cone the sample diameter grows as 2 t tan(aperture/2);
// the mip level whose voxels match that diameter is sampled trilinearly; samples are composited
// front to back. Steps are half the sample diameter (u_stepScale = 0.5), so each sample's
// opacity is corrected to the distance actually stepped: a' = 1 - (1 - a)^(step / diameter).
#include "common/shared.h"
#include "common/voxel_space.glsl"

layout(binding = 0) uniform sampler3D u_radiance;
uniform float u_stepScale;     // step length as a fraction of the sample diameter
uniform int u_maxSteps;

// Samples of the probed pixel's cones, for the viewer's cone inspector.
layout(std430, binding = VOXLAB_BINDING_CONE_SAMPLES) writeonly buffer ConeSamples { ConeSample coneSamples[]; };
layout(std430, binding = VOXLAB_BINDING_CONE_SAMPLE_COUNT) buffer ConeSampleCount { uint coneSampleCount; };

struct ConeResult {
  vec3 radiance;    // premultiplied accumulated radiance
  float opacity;    // accumulated opacity
  float opacityAt;  // accumulated opacity when the cone passed 'markDistance'
};

ConeResult traceCone(vec3 origin, vec3 dir, float aperture, float startDistance, float maxDistance,
                     float markDistance, int coneIndex, bool record) {
  float tanHalf = tan(0.5 * aperture);
  float t = startDistance;
  ConeResult r = ConeResult(vec3(0.0), 0.0, 0.0);
  bool marked = false;
  for (int step = 0; step < u_maxSteps && r.opacity < 0.99 && t < maxDistance; ++step) {
    float diameter = max(2.0 * tanHalf * t, u_voxelSize);
    float lod = log2(diameter / u_voxelSize);
    vec3 p = origin + dir * t;
    vec3 uvw = worldToVolumeUV(p);
    if (any(lessThan(uvw, vec3(0.0))) || any(greaterThan(uvw, vec3(1.0)))) break;
    if (!marked && t > markDistance) { r.opacityAt = r.opacity; marked = true; }
    vec4 s = textureLod(u_radiance, uvw, lod);
    float stepLength = diameter * u_stepScale;
    float a = 1.0 - pow(max(1.0 - s.a, 0.0), stepLength / diameter);
    vec3 c = s.a > 0.0 ? s.rgb * (a / s.a) : vec3(0.0);
    r.radiance += (1.0 - r.opacity) * c;
    r.opacity += (1.0 - r.opacity) * a;
    if (record) {
      uint k = atomicAdd(coneSampleCount, 1u);
      if (k < uint(VOXLAB_MAX_CONES * VOXLAB_MAX_SAMPLES_PER_CONE))
        coneSamples[k] = ConeSample(vec4(p, diameter), vec4(r.radiance, r.opacity), vec4(float(coneIndex), t, lod, a));
    }
    t += stepLength;
  }
  if (!marked) r.opacityAt = r.opacity;
  return r;
}
