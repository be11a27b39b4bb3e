// How another technique gets volumetric light over its image without glue code: append the
// volumetric stages to its stage list, naming the image resource to compose over.
#pragma once
#include <string>

#include "graph/technique.h"

namespace voxlab::volumetric {

// Adds density, phase, march, blur, upsample and compose to 't', which must already have the
// shadow-map and gbuffer stages (every technique that shades pixels has both). The compose stage
// reads 'surfaceResource' (an image of the G-buffer's size in linear radiance, e.g. vct-grid's
// "combined") and attenuates it by the medium; "" composes over direct light instead.
void appendVolumetricStages(Technique& t, const std::string& surfaceResource = "");

}  // namespace voxlab::volumetric
