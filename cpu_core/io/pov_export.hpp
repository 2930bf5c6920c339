// Writing a scene as a POV-Ray 3.7 scene, so an independent ray tracer can check ours.
//
// MAPPING (ours -> POV-Ray 3.7)
// - Coordinates: POV-Ray is left-handed, we are right-handed. Every point and vector is
//   written with z negated (a mirror), and the camera uses POV-Ray's default left-handed
//   `right x*aspect`: the mirror of a right-handed world seen through a left-handed
//   camera is the same picture (test PovOrientation checks it is not mirrored).
// - Camera: perspective, location/look_at/sky from ours, `up y`, `right x*aspect`
//   (aspect = width/height) and `direction z*0.5/tan(fov_y/2)`, so the vertical field of
//   view is fov_y exactly. POV-Ray keeps these lengths when it applies look_at, and its
//   pixel (X, Y) samples image point ((X + 0.5)/W, (Y + 0.5)/H) from the top left, as
//   CameraFrame::direction does (checked with edges at known positions): rendered at
//   (8 W, 4 H) with no antialiasing, 8x4 block means are our 32 samples per pixel exactly.
// - Output: `+FP16 File_Gamma=1.0` writes linear 16-bit values (no sRGB curve).
// - global_settings: assumed_gamma 1.0 (linear colours), ambient_light = scene ambient,
//   max_trace_level = max_depth + 1 (POV-Ray counts the camera ray as level 1),
//   adc_bailout 0 (no adaptive depth cut-off).
// - background { rgb background }; each light: light_source { position, color rgb I }, no
//   fade (no distance attenuation), `shadowless` when cast_shadows is false.
// - Triangles: one mesh2 per (object, material) with the triangle soup's vertices and
//   vertex normals (smooth, barycentric interpolation as ours).
// - Material: pigment rgbt <Od, T>, T = kt if kt > 0 else 1 - opacity;
//   finish { ambient ka  diffuse kd  phong ks  phong_size n  reflection { kr } };
//   interior { ior } when kt > 0.
//
// WHAT MATCHES EXACTLY (the comparison test stays inside this): ambient ka*Ia*Od,
// Lambert kd*Od*I*N.L with two-sided lighting, mirror reflection kr, refraction with
// transmit kt and ior on closed objects (POV-Ray's interior tracking agrees with our
// geometric-normal rule there), total internal reflection, hard shadows through
// transmitting blockers (shadow rays not refracted), coverage transparency of a material
// with kt = 0, ks = 0, kr = 0 (POV-Ray scales ambient and diffuse by 1 - transmit).
//
// RESIDUAL DIFFERENCES (not modelled identically; kept out of the comparison):
// - POV-Ray scales the ambient and diffuse terms of a transmitting surface by (1 - T);
//   we add kt * C_transmitted to the full local term. Equal when ka = kd = 0 on glass.
// - Shadows through glass: ours kt * Od, POV-Ray's transmit lets T through uncoloured.
//   Equal when Od = 1 on glass.
// - A material with both kt > 0 and opacity < 1 has no POV-Ray equivalent (one transmit).
// - Coverage transparency: POV-Ray does not scale reflection or highlights by opacity,
//   and counts a ray continued through a transparent surface as one more trace level.
// - Phong: the same formula on paper, ks * max(0, R.V)^n times the light colour, but not
//   the same pixels: with highlights (ks 0.3-0.5) the test scene drops from 67 dB to 53 dB
//   PSNR and 2.5 % of pixels differ by more than 2/255. The comparison uses ks = 0.
// - POV-Ray's own self-intersection tolerances and float geometry differ from our
//   double-precision offsets: single-pixel differences at silhouettes and shadow edges.
#pragma once
#include <string>

#include "scene/scene_data.hpp"

namespace abcube {

// The scene as POV-Ray 3.7 scene description text (see the mapping above).
std::string export_pov(const SceneData& scene);

}  // namespace abcube
