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

#include <string>
#include <vector>

namespace voxlab::detail {

// What the loader asks of image decoding: which images to decode (the others, e.g. normal maps
// no renderer reads, are skipped) and, on failure, one line naming the image and its file.
struct ImageDecodeRequest {
  std::vector<bool> wanted;        // per glTF image
  std::vector<std::string> uris;   // per glTF image, for messages ("" for embedded data)
  std::string error;               // set by decodeImage when it fails
};

// tinygltf image callback (TinyGLTF::SetImageLoader; user data: ImageDecodeRequest*): decodes
// any format stb_image reads into 8-bit RGBA.
bool decodeImage(tinygltf::Image* image, int index, std::string* err, std::string* warn, int reqWidth,
                 int reqHeight, const unsigned char* bytes, int size, void* user);

}  // namespace voxlab::detail
