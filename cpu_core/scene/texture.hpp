// Base-colour textures (docs/models-and-textures.md "Textures"): decoded once when the scene
// loads, sampled by every CPU path through one function (diffuse_color) and uploaded by the GL
// passes from the same linear pixels.
//
// THE RULE. The diffuse colour at a point of a triangle is
//   Od = material.color * texture(u, v)            (RGB; the texture's alpha is ignored)
// (u, v) interpolated with the point's barycentric weights from TriangleSoup::uvs (u right,
// v up the image, as OBJ's vt). A material without a texture has Od = material.color and
// costs no lookup. Images are decoded to linear RGB: 8- and 16-bit integer images (PNG,
// JPEG, ...) are sRGB-encoded and linearised, float images (EXR, HDR) are linear already;
// one channel is grey, a fourth (alpha) is dropped. The filtering is OpenImageIO's
// TextureSystem over the linear pixels (MIP-mapped in memory, bilinear within a level),
// wrap periodic (repeat) in both directions, as glTF's default. Lookups are point samples
// (zero derivatives: the finest level, bilinear): the 4x8 samples per pixel of the camera
// view and the map's texels do the antialiasing, as they do for geometry.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene_data.hpp"

namespace abcube {

class TextureSampler;

// One decoded texture: linear RGB floats, `width` x `height`, row 0 at the top of the
// image (v = 1), as the file stores it.
struct TextureImage {
  std::string name;  // for messages and stats: the file, or the embedded image's name
  int width = 0, height = 0;
  std::vector<float> rgb;
};

// Texels a texture may hold (refused above it when the scene loads: 4096 x 4096, 192 MiB
// of linear RGB floats, and as much again in the sampler's copy).
constexpr uint64_t MAX_TEXTURE_TEXELS = uint64_t{1} << 24;

// Decodes an encoded image (PNG, JPEG, EXR, ... whatever OpenImageIO reads; `name_hint`'s
// extension or the mime type helps it pick) into linear RGB. Returns false with `why` (a
// one-line reason, from OpenImageIO) when it cannot be decoded or is too large.
bool decode_texture(const unsigned char* bytes, size_t size, const std::string& name_hint, const std::string& mime_type,
                    TextureImage* out, std::string* why);

// A scene's textures: the decoded images, which material uses which, and one OpenImageIO
// TextureSystem over them (its own, cache bounded to 64 MiB; thread-safe, created once per
// loaded scene and shared by every render and thread of it).
class TextureSet {
 public:
  // material_image[m]: index into `images` of material m's texture, or -1.
  TextureSet(std::vector<TextureImage> images, std::vector<int> material_image);
  ~TextureSet();
  TextureSet(const TextureSet&) = delete;
  TextureSet& operator=(const TextureSet&) = delete;

  int image_of(uint32_t material) const { return material < material_image_.size() ? material_image_[material] : -1; }
  const std::vector<TextureImage>& images() const { return images_; }
  const std::vector<int>& material_image() const { return material_image_; }
  // The filtered linear RGB of image `image` at (u, v) (v up), wrapped periodically.
  glm::dvec3 sample(int image, const glm::dvec2& uv) const;

 private:
  std::vector<TextureImage> images_;
  std::vector<int> material_image_;
  std::unique_ptr<TextureSampler> sampler_;  // the image module's (io/image_module.hpp)
};

// The texture coordinates at barycentric weights `w` of triangle `triangle` ((0, 0) when
// the soup has none).
glm::dvec2 triangle_uv(const TriangleSoup& soup, uint32_t triangle, const glm::dvec3& w);

// Barycentric weights of point p (on or near the triangle's plane: it is projected) in
// triangle `triangle` of the soup, in double.
glm::dvec3 barycentric_weights(const TriangleSoup& soup, uint32_t triangle, const glm::dvec3& p);

// THE RULE above: Od at barycentric weights `w` of `triangle`.
inline glm::dvec3 diffuse_color(const SceneData& scene, uint32_t triangle, const glm::dvec3& w) {
  const uint32_t material = scene.triangles->material_id[triangle];
  const Material& m = scene.materials[material];
  if (!scene.textures) return m.color;
  const int image = scene.textures->image_of(material);
  if (image < 0) return m.color;
  return m.color * scene.textures->sample(image, triangle_uv(*scene.triangles, triangle, w));
}

// Od at point p of `triangle` (the A-buffer's fragments and the map's found points: the
// weights follow from the triangle and the point, nothing stored per fragment).
inline glm::dvec3 diffuse_color_at(const SceneData& scene, uint32_t triangle, const glm::dvec3& p) {
  const uint32_t material = scene.triangles->material_id[triangle];
  if (!scene.textures || scene.textures->image_of(material) < 0) return scene.materials[material].color;
  return diffuse_color(scene, triangle, barycentric_weights(*scene.triangles, triangle, p));
}

}  // namespace abcube
