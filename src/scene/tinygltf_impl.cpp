// The one translation unit that compiles tinygltf's implementation (and the stb_image decoder it
// uses). stb_image is compiled with static linkage, so none of its symbols leave this file and
// other parts of voxlab may use stb independently.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#endif
#define STB_IMAGE_STATIC
// Images wider or taller than 8192 pixels are refused by stb before it allocates their pixels: a
// PNG header may claim any size, and stb allocates width * height * channels before it reads one
// pixel (so at most 256 MiB for 8-bit RGBA). Real scenes' textures are at most 4096 wide.
#define STBI_MAX_DIMENSIONS 8192
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#define TINYGLTF_IMPLEMENTATION
#include "scene/tinygltf_config.h"
