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

namespace voxlab::detail {

bool decodeImage(tinygltf::Image* image, int index, std::string* err, std::string*, int, int,
                 const unsigned char* bytes, int size, void* user) {
  auto* request = static_cast<ImageDecodeRequest*>(user);
  const size_t i = size_t(index);
  if (request && i < request->wanted.size() && !request->wanted[i]) {
    image->width = image->height = 0;  // not used by any material voxlab reads
    return true;
  }
  int w = 0, h = 0, comp = 0;
  unsigned char* data = stbi_load_from_memory(bytes, size, &w, &h, &comp, 4);
  if (!data || w < 1 || h < 1) {
    if (data) stbi_image_free(data);
    std::string uri = request && i < request->uris.size() ? request->uris[i] : std::string();
    std::string text = "image " + std::to_string(index) + (uri.empty() ? std::string() : " ('" + uri + "')") +
                       " cannot be decoded (stb_image: " + (stbi_failure_reason() ? stbi_failure_reason() : "unknown") +
                       "); textures must be PNG, JPEG, TGA, BMP, PSD, GIF, HDR, PIC or PNM files";
    if (request) request->error = text;
    if (err) *err += text + "\n";
    return false;
  }
  image->width = w;
  image->height = h;
  image->component = 4;
  image->bits = 8;
  image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  image->image.assign(data, data + size_t(w) * size_t(h) * 4);
  stbi_image_free(data);
  return true;
}

}  // namespace voxlab::detail
