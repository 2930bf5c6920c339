// A camera fragment's base colour over the samples a shading point stands for (the
// --texture-lookups samples rule): the texture (texture.hpp) looked up where each sample's
// ray meets the fragment's triangle plane, and averaged, as the exact tracer's rays through
// those samples see it. The colour of a point is affine in its base colour, so with the
// light evaluated once at the point this is the mean of the samples' colours wherever the
// light varies less than the texture across them.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

#include "raster/abuffer.hpp"
#include "raster/raster.hpp"
#include "scene/scene_data.hpp"
#include "shading/resolve.hpp"

namespace abcube {

// Od of `triangle` averaged over the samples of `mask` (samples.hpp) of pixel (x, y) of
// `view`, on the triangle's plane; false, and nothing looked up, when its material has no
// texture or `mask` is empty.
bool mean_diffuse_color(const SceneData& scene, const RasterView& view, uint32_t triangle, int x, int y,
                        CoverageMask mask, glm::dvec3* od);

// Local Phong of a camera A-buffer fragment at the point it stands for (shading.hpp), no
// search: a textured one's base colour looked up there, or averaged over its covered
// samples (`texture_samples`, as above). The map methods' shader where nothing is searched,
// and the CPU side of the GPU cross-check.
PixelShader local_phong_shader(const SceneData& scene, const ABuffer& buffer, bool texture_samples);

}  // namespace abcube
