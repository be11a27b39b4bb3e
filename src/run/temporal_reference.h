// The reference of an animation: the CPU path tracer (reference/path_tracer.h, mode full, rays
// through pixel centres as the rasterizer's) renders every frame of an animated scene at a reduced
// size and sample count, posed as `voxlab run --frames N` poses it (frame k at time
// duration k / (N - 1)). Its flicker and energy are measured as run/frames.h measures a
// technique's final output (mean |I_k - I_(k-1)| over pixels and colour channels; the mean), and
// its noise floor is the same flicker between two renders of frame 0 with different seeds: the
// flicker the reference shows with nothing moving. Frames are cached as EXR files under
// 'cacheDir' (scene, size, spp and frame count in the path), so a second run reads them.
#pragma once
#include <string>
#include <vector>

namespace voxlab {

struct TemporalReference {
  std::string scene;
  int width = 0, height = 0, spp = 0, frames = 0;
  std::vector<double> energy;   // per frame, the image's mean
  std::vector<double> flicker;  // per frame from the second, mean |I_k - I_(k-1)|
  double meanFlicker = 0.0;
  double noiseFloor = 0.0;      // mean |I_0(seed 0) - I_0(seed 1)|
  double seconds = 0.0;         // rendering (0 when every frame came from the cache)
};

TemporalReference temporalReference(const std::string& sceneArgument, int frames, int width, int height, int spp,
                                    const std::string& cacheDir);

}  // namespace voxlab
