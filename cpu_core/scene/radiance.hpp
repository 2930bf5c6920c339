// THE RADIANCE BOUND: the largest value any pixel of any method can take on a scene, from the
// scene's own values; a scene whose bound passes MAX_RADIANCE is refused, so that no accepted
// scene writes a pixel that is not finite.
//
// Every colour a ray returns is a sum of non-negative terms (shading.hpp): the background, or a
// surface's ambient and light terms plus kr and kt times what its reflected and transmitted
// rays return (coverage opacity blends two such colours, which never exceeds the larger).
// The local terms of material m are at most
//   ka C_m A + sum_l I_l (kd C_m + ks),   C_m = max(colour) x the largest texel of its texture,
// A the largest ambient channel and I_l light l's largest channel (N.L <= 1, the specular
// power <= 1, shadows only dim). So a ray with d bounces left returns at most
//   M (1 + K + K^2 + ... + K^d),   M = max(background, the largest local terms), K = max(kr + kt),
// and a pixel, the mean of its samples, at most that with d = max_depth. The GPU computes in
// float: every partial sum is itself under the bound, so a bound under MAX_RADIANCE keeps
// float's arithmetic finite too.
#pragma once
#include <string>

#include "scene/scene_data.hpp"

namespace abcube {

// Far below float's 3.4e38, for the rounding of float sums on the way; far above any light
// a scene means (no distance attenuation: a light of 1 lights a white surface to 1).
constexpr double MAX_RADIANCE = 1e37;

// The bound on the scene's pixels at `max_depth` bounces (THE RADIANCE BOUND).
double radiance_bound(const SceneData& scene, int max_depth);

// Refuses (InputError) a scene whose bound at `max_depth` passes MAX_RADIANCE, naming the
// largest of the values that make it (background, ambient, a light's colour, a material's
// colour or texture) and how large that value may be. `where` prefixes the message (the
// scene's file and, for a render's own max_depth, the option).
void check_radiance(const SceneData& scene, int max_depth, const std::string& where);

}  // namespace abcube
