// The scene after loading: validated, triangulated, in world space (docs/scene-format.md).
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "base/bounds.hpp"

namespace abcube {

class TextureSet;  // scene/texture.hpp

struct Camera {
  glm::dvec3 position{0, 1, -4};
  glm::dvec3 look_at{0, 0.5, 0};
  glm::dvec3 up{0, 1, 0};
  double fov_y_deg = 60;
  int width = 512;
  int height = 512;
};

struct PointLight {
  glm::dvec3 position{0};
  glm::dvec3 color{1};  // intensity per channel, no distance attenuation
  bool cast_shadows = true;
};

// Phong material (thesis ch. 6; docs/scene-format.md "materials").
struct Material {
  std::string name;
  glm::dvec3 color{0.8};  // Od, diffuse colour
  double ambient = 1.0;   // ka, times the scene ambient
  double diffuse = 1.0;   // kd
  double specular = 0.0;  // ks
  double shininess = 32;  // n
  double reflect = 0.0;   // kr, mirror weight
  double transmit = 0.0;  // kt, refractive weight
  double ior = 1.0;
  double opacity = 1.0;  // coverage transparency, blended by the A-buffer resolve
  // Base colour texture: the image file, resolved (empty: none), or "#embedded/I" for
  // SceneData::embedded_images[I]. The diffuse colour at a point is color times the
  // texture at the point's uv (TriangleSoup::uvs).
  std::string texture;
};

struct SceneObject {
  std::string type;             // triangle, quad, box, sphere, mesh
  std::string path;             // "objects[3]" (for messages)
  uint32_t material = 0;        // index into SceneData::materials (per-triangle ids may differ for meshes)
  bool closed = false;          // has an inside (box, sphere, closed mesh)
  uint32_t first_triangle = 0;  // range in TriangleSoup
  uint32_t triangle_count = 0;
};

// Every object's triangles, unindexed, world space. Triangle i owns entries 3i..3i+2
// of positions and normals; normals are unit (flat ones repeated when the surface has
// no smooth normals). The winding gives the geometric normal cross(b-a, c-a).
// `uvs` is empty when no object has texture coordinates; otherwise it runs beside
// positions (3 per triangle), (0, 0) on triangles that have none.
struct TriangleSoup {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
  std::vector<uint32_t> object_id;    // per triangle, index into SceneData::objects
  std::vector<uint32_t> material_id;  // per triangle, index into SceneData::materials
  size_t triangle_count() const { return object_id.size(); }
};

// The scene's triangles, shared between copies of a SceneData: a render with another camera
// or other settings copies the SceneData (lights, materials, objects) but not its triangles.
// Reading is through -> and *; edit() gives the triangles to change, copying them first
// when another SceneData shares them (copy on write).
class SharedTriangles {
 public:
  SharedTriangles() : soup_(std::make_shared<TriangleSoup>()) {}
  const TriangleSoup* operator->() const { return soup_.get(); }
  const TriangleSoup& operator*() const { return *soup_; }
  TriangleSoup& edit() {
    if (soup_.use_count() > 1) soup_ = std::make_shared<TriangleSoup>(*soup_);
    return *soup_;
  }

 private:
  std::shared_ptr<TriangleSoup> soup_;
};

// An image carried inside a scene's own files (a glTF data: URI or a .glb buffer view),
// still encoded (PNG, JPEG, ...). The bytes are shared between copies of a SceneData.
struct EmbeddedImage {
  std::string name;       // for messages: "box.glb: images[0]"
  std::string mime_type;  // as the file declares it, may be empty
  std::shared_ptr<const std::vector<unsigned char>> bytes;
};

struct RenderSettings {
  // A render method's name. The core knows none: the host's registry of methods holds them,
  // and the loader checks the name against LoadLimits::methods.
  std::string method = "abuffer";
  int cube_resolution = 512;
  int max_depth = 4;
  bool fresnel = false;     // Schlick weights for kr/kt (shading.hpp secondary_weights); off = thesis
  double error_target = 0;  // > 0: choose cube_resolution from the Error_Parallax bound (plan.hpp)
  // > 0: the image reaches this PSNR (dB) against the exact tracer, by pilot renders
  // (host/render/target_db.hpp): the abuffer method chooses cube_resolution (overriding it and
  // error_target), the raytrace method its samples a pixel (overriding samples).
  double target_db = 0;
  // The raytrace method's camera samples a pixel: a rung of THE SAMPLE LADDER (samples.hpp).
  // The other methods shade the 32 samples of the A-buffer's masks, and the reference is 32.
  int samples = 32;
};
// The range a target PSNR may take, in dB: 8-bit images one code apart everywhere are 48 dB.
constexpr double MIN_TARGET_DB = 1, MAX_TARGET_DB = 100;

struct SceneData {
  std::string file;  // path as given, for messages
  Camera camera;
  glm::dvec3 background{0};
  glm::dvec3 ambient{0.1};
  std::vector<PointLight> lights;
  std::vector<Material> materials;
  std::vector<SceneObject> objects;
  SharedTriangles triangles;
  std::vector<EmbeddedImage> embedded_images;  // named by Material::texture "#embedded/I"
  // The materials' textures, decoded when the scene loaded (scene/texture.hpp); null when
  // no material has one. Shared between copies.
  std::shared_ptr<const TextureSet> textures;
  RenderSettings render;
  // Set when the camera was placed by framing ("frame": "all", model files): the
  // direction it looks along, so that a render that changes its size or field of view
  // frames again rather than cropping the old frame.
  std::optional<glm::dvec3> frame_direction;
  size_t dropped_triangles = 0;  // zero-area or non-finite triangles dropped at load
  // What loaded but is likely a mistake, one line each naming the place:
  // "scene.json: objects[2].file: warning: mesh \"empty.obj\" has no triangles".
  std::vector<std::string> warnings;

  Bounds bounds() const;
};

// Largest Euclidean distance from p to any scene vertex (0 for an empty scene).
double max_distance_from(const SceneData& scene, const glm::dvec3& p);

}  // namespace abcube
