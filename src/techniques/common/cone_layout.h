// Diffuse cone directions and weights for cone tracing.
//
// Directions are in tangent space (z = surface normal). Weights always sum to 1 so that the
// indirect diffuse estimate albedo * sum_i w_i L_i equals albedo * L under uniform incoming
// radiance L (a white furnace comes out right). "cosine" weights make w_i proportional to the
// cosine of cone i's axis with the normal (each cone covers the same solid angle), which is the
// quadrature of E / pi = (1/pi) * integral of L cos over the hemisphere; "equal" weights are right
// for the fibonacci layout, whose directions are already distributed by the cosine.
//
// Layouts:
//  ring:      one cone along the normal, the others evenly around it, tilted by
//             min(aperture, 90 deg - aperture / 4) from the normal (6 x 60 deg: tilt 60 deg, the
//             classic layout of Crassin et al.);
//  fibonacci: a cosine-distributed Fibonacci spiral (deterministic).
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace voxlab {

struct Cone {
  glm::vec3 direction;  // unit, tangent space
  float weight;
};

std::vector<Cone> diffuseCones(int count, float apertureRadians, const std::string& layout,
                               const std::string& weighting);

}  // namespace voxlab
