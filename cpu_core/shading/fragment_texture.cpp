#include "shading/fragment_texture.hpp"

#include "base/samples.hpp"
#include "material/shading.hpp"
#include "scene/texture.hpp"

namespace abcube {

bool mean_diffuse_color(const SceneData& scene, const RasterView& view, uint32_t triangle, int x, int y,
                        CoverageMask mask, glm::dvec3* od) {
  if (!scene.textures || scene.textures->image_of(scene.triangles->material_id[triangle]) < 0) return false;
  glm::dvec3 sum(0.0);
  int n = 0;
  for (int k = 0; k < MASK_SAMPLES; ++k) {
    if (!((mask >> k) & 1u)) continue;
    const glm::dvec3 p = point_on_triangle_plane(view, *scene.triangles, triangle, x + sample_dx(k), y + sample_dy(k));
    sum += diffuse_color_at(scene, triangle, p);
    ++n;
  }
  if (n == 0) return false;
  *od = sum / double(n);
  return true;
}

PixelShader local_phong_shader(const SceneData& scene, const ABuffer& buffer, bool texture_samples) {
  return [&scene, &buffer, texture_samples](const Fragment& f, int x, int y) {
    const Material& m = scene.materials[scene.triangles->material_id[f.triangle()]];
    const glm::dvec3 p = fragment_point(buffer, *scene.triangles, f, x, y);
    glm::dvec3 od;
    if (!texture_samples || !mean_diffuse_color(scene, buffer.view, f.triangle(), x, y, f.mask, &od)) {
      od = diffuse_color_at(scene, f.triangle(), p);
    }
    return ShadedFragment{phong_local(m, p, f.shading_normal(), scene.camera.position, scene.ambient, scene.lights, od),
                          m.opacity};
  };
}

}  // namespace abcube
