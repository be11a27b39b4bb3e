// The CPU reference path tracer: ground truth for every voxel GI technique in voxlab.
//
// It renders the same voxlab::Scene the GPU techniques see (world-space triangles, Lambertian
// albedo = baseColor.rgb x sRGB-decoded base colour texture, emissive radiance, KHR punctual
// lights evaluated with scene/light_model.h) on Embree 3.
//
// Light transport, counted in diffuse reflections r between the emitter and the eye:
//   r = 0  emission seen directly;  r = 1  direct lighting;  r = 2  one indirect bounce; ...
// In a closed white furnace (albedo rho, emission Le) the sum over r <= k is
// Le (1 - rho^(k+1)) / (1 - rho). The modes keep:
//   direct      r in {0, 1}      -> furnace Le (1 + rho)
//   one-bounce  r in {0, 1, 2}   -> furnace Le (1 + rho + rho^2)
//   two-bounce  r in {0, ..., 3} -> furnace Le (1 + rho + rho^2 + rho^3): direct and two indirect
//               bounces, what vct-grid's combined approximates with bounces=2
//   indirect    r >= 2           -> furnace Le rho^2 / (1 - rho)   (= full - direct)
//   indirect-1  r == 2           -> furnace Le rho^2                (= one-bounce - direct): exactly
//               one indirect bounce, what a single-bounce GI technique (e.g. vct-grid's
//               indirect-diffuse: one diffuse gather of the direct-lit voxels) approximates
//   indirect-2  r in {2, 3}      -> furnace Le (rho^2 + rho^3) (= two-bounce - direct)
//   indirect-K  r in {2, ..., K+1}, K = 1..8 -> furnace Le (rho^2 + ... + rho^(K+1)): K indirect
//               bounces, what a technique that gathers K diffuse bounces approximates (e.g.
//               voxel-path-tracing's paths of paths.bounces = K); indirect-1 and indirect-2 are
//               the cases K = 1 and 2
//   full        r >= 0           -> furnace Le / (1 - rho)
//   ao          cosine-weighted visible fraction V at the first hit, rays up to aoRadius long
// An optional constant sky (setSkyRadiance) is one more emitter: a ray that escapes carries it,
// counted as light already reflected once (so what it lights is indirect, see setSkyRadiance).
//
// Estimator: at each path vertex, next-event estimation towards every punctual light (one shadow
// ray each, the light model evaluated exactly) and towards one point on the emissive triangles
// (picked by area x emitted luminance, uniform on the triangle), combined with cosine-weighted
// BSDF sampling by multiple importance sampling (power heuristic). Surfaces reflect on both sides;
// triangles emit on their front side only (the side their vertex normals point to). Russian
// roulette starts after the third reflection (continuation probability = max albedo component,
// capped at 0.95), so full and indirect are unbiased; a hard cap of 1024 reflections adds a bias
// below 0.95^1021 (negligible).
//
// Random numbers come from a counter-based hash of (pixel or point key, sample index, reflection
// index, dimension): no RNG state is shared, so images do not depend on the thread count.
#pragma once
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "reference/image.h"
#include "scene/scene.h"

namespace voxlab::reference {

// A mode: a kind, and for IndirectBounces the number of indirect bounces K (r in {2, ..., K+1}).
// Mode::Full, Mode::Direct, ... convert to a Mode; Mode::indirect(K) makes indirect-K.
struct Mode {
  enum Kind { Full, Direct, OneBounce, TwoBounce, Indirect, IndirectBounces, AO };
  static constexpr int kMaxIndirectBounces = 8;

  Kind kind = Full;
  int bounces = 0;  // IndirectBounces only: K in 1..kMaxIndirectBounces

  constexpr Mode(Kind k = Full) : kind(k) {}
  static constexpr Mode indirect(int k) {
    Mode m(IndirectBounces);
    m.bounces = k;
    return m;
  }
  static const Mode IndirectOne;  // indirect-1: r == 2
  static const Mode IndirectTwo;  // indirect-2: r in {2, 3}

  // Counts indirect light only (no emission seen directly, no direct lighting): indirect, indirect-K.
  constexpr bool indirectOnly() const { return kind == Indirect || kind == IndirectBounces; }
  friend constexpr bool operator==(const Mode& a, const Mode& b) { return a.kind == b.kind && a.bounces == b.bounces; }
  friend constexpr bool operator!=(const Mode& a, const Mode& b) { return !(a == b); }
};
inline constexpr Mode Mode::IndirectOne = Mode::indirect(1);
inline constexpr Mode Mode::IndirectTwo = Mode::indirect(2);

std::string modeName(Mode mode);  // "full", "direct", "one-bounce", "two-bounce", "indirect", "indirect-K", "ao"
// Every mode by name: full, direct, one-bounce, two-bounce, indirect, indirect-1 .. indirect-8, ao.
std::vector<std::string> modeNames();
// The valid forms in one line, for error messages: "full, direct, ..., indirect-K (K = 1..8), ao".
std::string modeForms();
Mode parseMode(const std::string& name);       // throws voxlab::Error naming the valid forms

struct ReferenceSettings {
  Mode mode = Mode::Full;
  int spp = 16;                  // samples per pixel, 1..1000000
  int width = 512;
  int height = 512;
  int cameraIndex = 0;           // into Scene::cameras
  float aoRadius = INFINITY;     // ao mode: occluders farther than this do not count
  int threads = 0;               // 0: $VOXLAB_THREADS when set, else all hardware threads
  uint64_t seed = 0;             // changes every random number; 0 is the default sequence
  bool pixelJitter = false;      // false: every ray through the pixel centre (as a rasteriser);
                                 // true: uniformly jittered within the pixel (box filter)
  bool computeStdErr = true;     // fill Image::stdErr
  // Called with the fraction done (0..1) from the calling thread; may be empty.
  std::function<void(double)> progress;
};

struct RenderStats {
  uint64_t rays = 0;        // every Embree query: camera, extension and shadow rays
  double seconds = 0.0;     // wall-clock time of the render
  int threads = 0;          // threads used
  double raysPerSecond() const { return seconds > 0 ? double(rays) / seconds : 0.0; }
};

// Mean and standard error of the mean of a Monte Carlo estimate, per channel.
struct Estimate {
  glm::dvec3 mean{0.0};
  glm::dvec3 stdErr{0.0};
  uint64_t samples = 0;
};

// Number of threads a setting of 0 resolves to ($VOXLAB_THREADS, else hardware concurrency).
int defaultThreadCount();

class ReferenceTracer {
 public:
  // Builds the Embree scene and the emitter tables; the Scene must outlive the tracer.
  explicit ReferenceTracer(const Scene& scene);
  ~ReferenceTracer();
  ReferenceTracer(const ReferenceTracer&) = delete;
  ReferenceTracer& operator=(const ReferenceTracer&) = delete;

  // Renders one camera image. Throws voxlab::Error on invalid settings (spp, size, camera).
  Image render(const ReferenceSettings& settings, RenderStats* stats = nullptr) const;

  // Radiance arriving at 'origin' from direction -dir (i.e. carried along the ray origin + t dir),
  // restricted to the mode's reflection counts (ao: visible fraction at the first hit).
  Estimate estimateRadiance(const glm::vec3& origin, const glm::vec3& dir, Mode mode, int samples,
                            uint64_t key = 0, float aoRadius = INFINITY, int threads = 1) const;

  // Irradiance E at point p on a virtual Lambertian surface with unit normal n that is not part of
  // the scene (it neither occludes nor reflects). Mode counts reflections as if that surface were
  // the first hit: direct = light arriving straight from emitters and punctual lights; one-bounce
  // adds light reflected once by the scene; indirect = light reflected at least once by the scene.
  Estimate estimateIrradiance(const glm::vec3& p, const glm::vec3& n, Mode mode, int samples,
                              uint64_t key = 0, int threads = 1) const;

  // Cosine-weighted visible fraction V at p around n: the fraction of cosine-distributed rays
  // that hit nothing within 'radius'. One ray per sample (V's estimator is a 0/1 variable).
  Estimate estimateAO(const glm::vec3& p, const glm::vec3& n, int samples, float radius = INFINITY,
                      uint64_t key = 0, int threads = 1) const;

  // The tracer's own ray queries (alpha-masked texels let rays through), for the other CPU
  // references (single_scattering.h): the distance to the first surface along o + t d (INFINITY
  // for none), and whether a surface lies on o + t d for t in [0, tfar).
  float firstHit(const glm::vec3& o, const glm::vec3& d) const;
  bool occluded(const glm::vec3& o, const glm::vec3& d, float tfar) const;

  const Scene& scene() const { return scene_; }

  // Constant sky (environment) radiance, W/(m^2 sr) per channel, 0 by default: every ray that
  // leaves the scene without a hit carries it. Seen by the camera it counts as r = 0. Seen by a
  // bounce ray from reflection r it counts as r + 1: the sky stands for light that has already
  // been reflected once (a lit environment), and every voxel technique gathers it with the same
  // cones or rays as its indirect light, so the light it reflects off a surface is in indirect-1,
  // not in direct (whose techniques' outputs hold the punctual lights and emission only),
  // reached by the cosine-weighted BSDF rays only (no next-event estimation: a uniform sky has
  // no direction to sample, and cosine sampling carries it at zero variance on an open plane).
  // The sky furnace: an albedo-1 object under it has radiance L everywhere (full mode).
  void setSkyRadiance(const glm::vec3& radiance);
  glm::vec3 skyRadiance() const;

  struct Impl;

 private:
  const Scene& scene_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace voxlab::reference
