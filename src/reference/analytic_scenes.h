// Procedural scenes with known answers, for validating the reference path tracer (and, through
// it, every technique). Each builder returns an ordinary voxlab::Scene (world-space triangles,
// materials, one camera) and the functions next to it give the analytic value to expect.
// Formulas: /work/shared/guide/reference-data.md ("Analytic ground truths").
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace voxlab::reference::analytic {

// Accumulates triangles per material and produces a Scene whose draw ranges are contiguous.
class SceneBuilder {
 public:
  explicit SceneBuilder(std::string name);
  uint32_t material(const std::string& name, glm::vec3 albedo, glm::vec3 emissive = glm::vec3(0.0f));
  // One triangle; its front side (the side it emits on, and its stored normal) is 'facing'
  // (the winding is reversed when needed so that the winding and the normal agree).
  void triangle(glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t material, glm::vec3 facing);
  // Planar quad p0 p1 p2 p3 (in order around its edge), front side 'facing'.
  void quad(glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, uint32_t material, glm::vec3 facing);
  void camera(const std::string& name, glm::vec3 position, glm::vec3 forward, glm::vec3 up, float yfov);
  Scene build() const;

 private:
  struct Tri {
    glm::vec3 p[3];
    glm::vec3 n;
  };
  Scene base_;
  std::vector<std::vector<Tri>> perMaterial_;
};

// --- White furnace -------------------------------------------------------------------------------
// Closed cube [-size/2, size/2]^3, every face of albedo rho emitting Le toward the inside. The
// camera "inside" sits at the centre looking down -z. Radiance everywhere inside after up to k
// reflections: Le (1 - rho^(k+1)) / (1 - rho); all reflections: Le / (1 - rho).
Scene furnaceBox(float rho, glm::vec3 Le, float size = 1.0f);
double furnaceRadiance(double rho, double Le, int maxReflections /* -1 = all */);

// --- Ambient occlusion next to a wall -----------------------------------------------------------
// Floor y = 0 (albedo 0.5, square of half-size floorHalf) and a wall in the plane x = d spanning
// y in [0, h] and z in [-halfLength, halfLength], facing -x. Query point: the origin, normal +y.
Scene floorAndWall(float d, float h, float halfLength, float floorHalf);
// V = 1/2 (1 + d / sqrt(d^2 + h^2)) for an infinitely long wall of height h at distance d.
double aoNextToInfiniteWall(double d, double h);
// The same for a wall of finite length 2 halfLength centred on the query point (closed form of
// 1 - the form factor from the point to the wall; bounds the "infinitely long" residual).
double aoNextToFiniteWall(double d, double h, double halfLength);

// --- Ambient occlusion under a sphere -----------------------------------------------------------
// Floor y = 0 and a UV sphere (segments around, rings from pole to pole; vertices on the sphere)
// of radius r centred at (0, H, 0). Query point: the origin, normal +y.
Scene floorAndSphere(float r, float H, int segments, int rings);
double aoUnderSphere(double r, double H);  // V = 1 - (r/H)^2

// --- Rectangular emitter over a floor point -----------------------------------------------------
// Emitter: the rectangle [x0, x1] x [z0, z1] at height c, facing down (-y), albedo 0, radiance Le;
// floor y = 0 of albedo floorAlbedo (half-size floorHalf). Query: a floor point, normal +y.
Scene rectEmitterOverFloor(float x0, float x1, float z0, float z1, float c, glm::vec3 Le,
                           float floorAlbedo = 0.5f, float floorHalf = 10.0f);
// Form factor from a differential area to a parallel a x b rectangle at height c with one corner
// straight above it: F = 1/(2 pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))].
double cornerFormFactor(double a, double b, double c);
// Form factor from the floor point (px, pz) to the rectangle [x0,x1] x [z0,z1] at height c (the
// point's projection inside the rectangle): the sum of four corner terms. Irradiance = pi Le F.
double formFactorUnderRectangle(double px, double pz, double x0, double x1, double z0, double z1,
                                double c);

}  // namespace voxlab::reference::analytic
