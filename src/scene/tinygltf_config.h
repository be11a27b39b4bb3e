// Private to src/scene: includes tinygltf configured for Debian's packages (system nlohmann-json,
// stb under /usr/include/stb/, no image writing). Every file that includes tiny_gltf.h must go
// through this header so that all translation units see the same configuration; the
// implementation itself is compiled once, in tinygltf_impl.cpp.
#pragma once

#define TINYGLTF_NO_INCLUDE_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include <tiny_gltf.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
