// Scene: what every technique, the CPU references and the viewer see of a glTF file.
//
// The loader flattens the node hierarchy: every triangle is stored in world space (metres),
// grouped by material into draw ranges, so the GPU path, the CPU voxelizer and the reference
// path tracer all read the same arrays. Lights follow KHR_lights_punctual; the one radiometric
// model every renderer uses for them is in scene/light_model.h (and shaders/common/lights.glsl).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace voxlab {

struct Bounds {
  glm::vec3 min{1e30f};
  glm::vec3 max{-1e30f};
  void extend(const glm::vec3& p) { min = glm::min(min, p); max = glm::max(max, p); }
  bool valid() const { return min.x <= max.x && min.y <= max.y && min.z <= max.z; }
  glm::vec3 center() const { return 0.5f * (min + max); }
  glm::vec3 extent() const { return max - min; }
};

// 8-bit RGBA image as stored in the file (base colour textures are sRGB-encoded).
struct TextureImage {
  std::string name;
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba8;  // width * height * 4, row 0 at the top (glTF UV v = 0)
};

// glTF alphaMode. BLEND is drawn as OPAQUE: voxlab has no transparency.
enum class AlphaMode { Opaque, Mask, Blend };

struct Material {
  std::string name;
  glm::vec4 baseColor{1.0f};         // linear RGBA factor (Lambertian albedo = rgb)
  int baseColorTexture = -1;         // index into Scene::textures, -1 = none
  glm::vec3 emissive{0.0f};          // linear emitted radiance (factor * strength)
  int emissiveTexture = -1;          // index into Scene::textures, -1 = none
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alphaCutoff = 0.5f;          // MASK: no surface where baseColor.a x texture alpha < this
  // glTF doubleSided. Every renderer in voxlab lights both sides of every surface (the G-buffer
  // turns normals to the viewer, the reference tracer reflects on both sides, voxels have no
  // side), which is what doubleSided = true asks for; single-sided materials are not culled.
  bool doubleSided = false;
};

enum class LightType { Directional, Point, Spot };

// A KHR_lights_punctual light placed in the world. Units follow the extension, read as
// radiometric quantities: 'intensity' is radiant intensity (W/sr) for point and spot lights and
// irradiance (W/m^2) for directional lights.
struct Light {
  std::string name;
  LightType type = LightType::Point;
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, -1.0f, 0.0f};  // unit vector the light travels along
  glm::vec3 color{1.0f};
  float intensity = 1.0f;
  float range = 0.0f;                       // 0 = infinite
  float innerConeAngle = 0.0f;              // radians, spot only
  float outerConeAngle = 0.785398163f;      // radians, spot only (pi/4 as in the extension)
};

struct Camera {
  std::string name;
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};  // unit
  glm::vec3 up{0.0f, 1.0f, 0.0f};        // unit, orthogonal to forward
  float yfov = 0.8f;                     // radians
  float znear = 0.01f;
  float zfar = 100.0f;                   // 0 in the file (infinite) is stored as 100
  glm::mat4 view() const;
  glm::mat4 projection(float aspect) const;
};

// A camera on the +z side of the bounds looking down -z (up +y) whose vertical field of view
// yfov (radians) contains the bounding sphere; used when a file has no camera.
Camera frameBounds(const Bounds& bounds, float yfov);

// Sun directions as angles (degrees): the sun stands at 'elevation' above the horizontal plane
// (glTF's +y is up) and at 'azimuth' measured about +y from +z toward +x. The light travels
// along -(cos(el) sin(az), sin(el), cos(el) cos(az)).
glm::vec3 sunDirection(float azimuthDeg, float elevationDeg);
void sunAngles(const glm::vec3& direction, float& azimuthDeg, float& elevationDeg);

// The light a scene without lights gets: a white directional sun from above and to the side
// (elevation 60 degrees, azimuth 30 degrees, so the picture has shadows and bounce light) with an
// irradiance of 5 W/m^2, the same as the checked-in Sponza's sun, which the default exposure
// shows. A directional light needs no position, so the direction holds for any scene size; its
// shadow map is fitted to the scene's bounds. Named kDefaultSunName.
inline constexpr const char* kDefaultSunName = "default sun (scene has none)";
Light defaultSun();
// The camera a scene without cameras gets: frameBounds() of its bounds at the default field of
// view, named so that the stderr notice, the manifest and the viewer say where it came from.
inline constexpr const char* kFramingCameraName = "framing camera (scene has none)";

// Triangles [firstIndex/3, firstIndex/3 + indexCount/3) all use one material.
struct DrawRange {
  uint32_t firstIndex = 0;
  uint32_t indexCount = 0;
  uint32_t material = 0;
};

// Vertices [first, first + count) of the scene.
struct VertexRange {
  uint32_t first = 0;
  uint32_t count = 0;
};

struct Scene {
  std::string name;  // file stem, e.g. "cornell-box"
  std::string path;  // file it was loaded from
  // Vertex arrays, world space, one entry per vertex.
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;    // unit; computed (area-weighted) where the file has none
  std::vector<glm::vec2> uvs;        // (0,0) where the file has none
  std::vector<uint32_t> indices;     // 3 per triangle, sorted so each DrawRange is contiguous
  std::vector<DrawRange> draws;
  std::vector<Material> materials;   // never empty: a default white material is added if needed
  std::vector<TextureImage> textures;
  std::vector<Light> lights;         // never empty: defaultSun() is added if the file has none
  std::vector<Camera> cameras;       // never empty: a framing camera is added if the file has none
  Bounds bounds;                     // of all triangles
  // Constant sky radiance (W/(m^2 sr), grey) of an open scene: the default of the sky.radiance
  // parameter and of `voxlab reference --sky`. From the glTF scene's extras "sky_radiance"
  // (a number >= 0); 0, no sky, when absent.
  float skyRadiance = 0.0f;
  // The vertices placed by nodes that an animation moves (the node or one above it is animated;
  // SceneAnimation::moving holds what posing them needs). Empty for a still scene. The scene's
  // static part is every triangle outside them, its dynamic part every triangle inside.
  std::vector<VertexRange> movingVertices;

  size_t triangleCount() const { return indices.size() / 3; }
  uint32_t triangleMaterial(size_t triangle) const;  // via draws
  // Whether an animation moves 'triangle' (its vertices lie in movingVertices: a primitive's
  // triangles use only that primitive's vertices, all placed by one node).
  bool triangleMoves(size_t triangle) const;
  size_t movingTriangleCount() const;
};

// Loads a glTF 2.0 file (.gltf or .glb). Throws voxlab::Error with one line naming the file and
// what is wrong (missing buffer file, out-of-range index, NaN/Inf position, wrong JSON types,
// node cycle, unsupported required extension, glTF 1.0, no triangles).
Scene loadScene(const std::string& path);

// Resolves a scene argument: a path to a file, or the name of a scene in scenes/ ("cornell-box").
// Throws Error listing the scenes in scenes/ when neither exists.
std::string resolveScenePath(const std::string& nameOrPath);
// Names of the scenes in scenes/: the stems of scenes/*.gltf and *.glb, and the folders
// scenes/<name>/ holding <name>.gltf or <name>.glb (a scene with its own buffer and textures).
std::vector<std::string> listScenes();

}  // namespace voxlab
