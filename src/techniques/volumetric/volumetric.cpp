// volumetric: light shafts through smoke and haze by ray-marched single scattering.
//
// Intro
//   Light scattered by a participating medium (smoke, dust, haze) towards the camera makes the
//   light's cone and the shadows of objects in it visible. After Vos 2014 (Killzone Shadow Fall)
//   as seed 000 implements it: particles deposit amounts of scattering into a 3D grid, and a
//   screen-space pass marches every camera ray to its surface, tests each sample against the
//   light's shadow map and adds the light the Henyey-Greenstein phase function sends towards the
//   camera. Dithered start offsets trade the banding of few samples for noise, which a bilateral
//   blur removes; the march runs at half resolution and is upsampled along surfaces.
//
// Overview (the stages, in order)
//   1. density     particles -> R32UI counts (integer atomics) -> sigma_s volume (1/m)
//   2. phase       p(mu) for the current g: samples, a plot, the integrals in the statistics
//      light       the scene's first light after the light.0.* parameters (shared, common/light_stage)
//   3. shadow-map  the shared light model and shadow map (spot: perspective; sun: orthographic)
//   4. gbuffer     the shared G-buffer: the surface each camera ray ends on
//   5. march       iterative, one sample index per iteration: in-scattered radiance and
//                  transmittance per marched pixel, the probed pixel's ray record
//   6. blur        bilateral, x then y, a kernel of period 4 (the dither tile)
//   7. upsample    bilateral, to the G-buffer's resolution
//   8. compose     surface * T + L_in, tonemapped
//
// Details
//   - The estimator (what the physics needs; the thesis' Listing 4.52 has none of sigma_s, dt
//     and T, and averages over the step count instead):
//       L_in = sum_i T(t_i) sigma_s(x_i) p(mu_i) E(x_i) V(x_i) dt,   t_i = t0 + (i + u) dt,
//     dt = (t1 - t0) / N over the part of the camera ray inside the density grid and before the
//     surface, u the pixel's dither offset, E the light's irradiance at x_i
//     (src/scene/light_model.h: I / d^2 with the spot falloff, or a sun's E), V the shadow-map
//     test (0 outside the map), mu = dot(ray direction, unit vector to the light), and
//     T(t_i) = exp(-(sum_{j<i} sigma_t(x_j) dt + sigma_t(x_i) u dt)) (exact for a homogeneous
//     medium). The surface behind is attenuated by T(t1) = exp(-sum_j sigma_t(x_j) dt). Units: the
//     result is radiance, W/(m^2 sr), in the units of the scene's lights.
//   - The medium: sigma_s(x) = (medium.particle-optical-depth * count(x) (trilinear, zero
//     outside the grid) + medium.haze-optical-depth inside the grid) / L, L the scene's largest
//     extent; sigma_t = extinction-ratio * sigma_s. The coefficients are optical depths over the
//     scene, not 1/m, so one set of defaults suits a 0.56 m box and a 37 m atrium alike (in 1/m
//     the Cornell box's haze made Sponza a fog: mean transmittance 0.023); stages.h has the
//     constants, the stage statistics the resulting 1/m values. g (medium.anisotropy) is one global parameter in (-1, 1). The thesis instead used
//     the density as g (g = 1 - clamp(255 density)): empty space became "g = 1" rather than
//     sigma_s = 0.
//   - Henyey-Greenstein with the (1 - g^2) numerator (shaders/volumetric/phase.glsl); the
//     thesis' (1 - g)^2 integrates to (1 - g)/(1 + g) and stays selectable (march.phase=thesis)
//     to show it. The base 1 + g^2 - 2 g mu is kept positive and mu clamped, so no NaN near g = 1.
//   - The dither offset is Bayer(x mod 4, y mod 4) / 16 of a step, x indexing the first
//     dimension as in Listing 4.51 (shaders/volumetric/volumetric_shared.h). Over one 4x4 tile
//     the 16 offsets are k/16, so for rays seeing the same integrand the tile mean of the N-step
//     estimates is exactly the 16N-interval left Riemann sum; the thesis' 0.22 breaks that
//     (march.dither=thesis-0.22 keeps it to show). The blur kernel (taps -r..r, end taps 1/2)
//     weighs each phase mod 4 equally for even r, so the blur realises that mean on flat regions.
//   - Clipping to a spot's cone (march.clip=spot-cone, after Vos 2014 section 3.2.1): outside
//     the spot's outer cone E = 0, so the N samples go only to the part [a, b] of [t0, t1] inside
//     the cone (one interval: the cone is convex below 90 degrees; widened by 0.01 rad at the rim),
//     dt = (b - a) / N; the parts [t0, a] and [b, t1] still attenuate, so their optical depth is
//     integrated apart (N midpoint samples each, at the first and after the last sample). A
//     narrow spot (25 degrees) at 8 samples: image error 7.8 % -> 0.19 %, worst 8x8 block 3.6x the
//     image mean -> 2.3 % (VolumetricConeClip.*). Off by default (the goldens and the lesson use
//     the thesis' march); no effect under a sun.
//   - The probe: probe.x / probe.y are a screen probe (a click on a camera image picks the pixel),
//     and the ray record is its probe record, drawn and checked by
//     src/techniques/volumetric/views/volumetric_ray.cpp (T never rising, each contribution equal to
//     T sigma_s p E V dt of its own terms, the running sum).
//   - Bilateral weights: a Gaussian in the relative surface-distance difference (sigma 2 %);
//     "no surface" pixels only mix with each other. The sources give no kernels (unclear there).
//   - Neglected, as in the sources: the medium does not attenuate the light on its way to a
//     sample or to a surface, it does not shadow itself, and the cone-traced reflections of
//     vct-grid do not see it (seed 000 lines 3597-3600).
//   - Sizes: the particle list is sized from particles.count (at most 4e6, 64 MiB), the grids
//     from density.resolution (at most 256^3, 128 MiB for both), the ray record from march.steps
//     (at most 256): the parameter ranges refuse larger values before anything is allocated.
//   - Composing over another technique: appendVolumetricStages (volumetric.h) adds these stages
//     to any technique with a shadow map and a G-buffer and composes over a named image of it
//     (compose.surface=input), e.g. vct-grid's "combined"; tests/unit/test_volumetric.cpp builds
//     such a technique. The registered technique composes over its own direct light.
//
// References
//   seed 000 (Gomes) section 2.5 (Vos's method, Eq. 1, dithering, bilateral blur and upsampling)
//   and section 4.5 (Listings 4.50-4.53, Table 2); Vos, "Volumetric Light Effects in Killzone:
//   Shadow Fall", GPU Pro 5, 2014; Henyey and Greenstein, "Diffuse radiation in the galaxy",
//   1941. The reference the tests compare with is src/reference/single_scattering.h.
#include "techniques/volumetric/volumetric.h"

#include "techniques/common/gbuffer_stage.h"
#include "techniques/common/light_stage.h"
#include "techniques/common/shadow_map_stage.h"
#include "techniques/volumetric/stages.h"

namespace voxlab::volumetric {

void appendVolumetricStages(Technique& t, const std::string& surfaceResource) {
  t.add<DensityStage>(false);
  t.add<PhaseStage>();
  t.add<MarchStage>();
  t.add<BlurStage>();
  t.add<UpsampleStage>();
  t.add<ComposeStage>(surfaceResource);
}

static std::unique_ptr<Technique> makeVolumetric() {
  auto t = std::make_unique<Technique>(
      "volumetric", "Volumetric light by ray-marched single scattering",
      "Smoke particles fill a density grid; camera rays march through it with shadow-mapped, Henyey-Greenstein "
      "single scattering, dithered, blurred and upsampled, then composed over the lit surfaces.");
  t->add<DensityStage>();
  t->add<PhaseStage>();
  t->add<LightStage>();
  t->add<ShadowMapStage>();
  t->add<GBufferStage>();
  t->add<MarchStage>();
  t->add<BlurStage>();
  t->add<UpsampleStage>();
  t->add<ComposeStage>();
  t->setFinalOutput("compose", "final");
  return t;
}

VOXLAB_REGISTER_TECHNIQUE("volumetric", "Volumetric light by ray-marched single scattering", makeVolumetric);

}  // namespace voxlab::volumetric
