// Internal to scene loading (scene_load.hpp): what reading the objects shares between the
// scene readers (scene_load.cpp) and the mesh loader (scene_mesh.cpp).
#pragma once
#include <cstdint>
#include <map>
#include <utility>
#include <optional>
#include <string>

#include "scene/framing.hpp"
#include "scene/scene_data.hpp"
#include "scene/scene_json.hpp"
#include "scene/scene_load.hpp"
#include "scene/tessellate.hpp"

namespace abcube::detail {

constexpr size_t MAX_TRIANGLES = size_t{1} << 26;  // 67M triangles, ~5 GiB of soup
constexpr const char* DEFAULT_MATERIAL = "(default)";

// What loading the objects shares: the scene being filled, the caller's limits (root
// canonical, or empty), material names, and the materials already made from MTL files
// (keyed by resolved OBJ path and MTL name).
struct LoadState {
  const Source& src;
  SceneData& scene;
  const LoadLimits& limits;
  std::string root;
  std::map<std::string, uint32_t> material_by_name;
  std::map<std::string, uint32_t> mtl_materials;
  int default_material = -1;
  // Each texture file a material names (resolved), with where it was named for messages:
  // the field path and a prefix ("" or "\"a.mtl\":12: map_Kd ").
  std::map<std::string, std::pair<std::string, std::string>> texture_place;
  // The first perspective camera of a gltf object with "use_camera" (world space).
  std::optional<Camera> file_camera;
  // memory_budget_bytes(limits.max_memory_bytes()), read once when loading starts.
  uint64_t memory_budget = 0;
};

// ---- The sections (scene_sections.cpp) ----

// The camera section; with "frame": "all" its position and look_at are placed once the
// objects are loaded (frame_camera), along "direction".
struct CameraSection {
  Camera camera;
  bool frame = false;
  glm::dvec3 direction = DEFAULT_FRAME_DIRECTION;
};
CameraSection read_camera(const Fields& f);
PointLight read_light(const Fields& f);
// Phong material with the format's defaults (docs/scene-format.md "materials").
Material read_material(const Fields& f, const std::string& name);
// `methods`: the names render.method may take (empty: any name but "").
RenderSettings read_render(const Fields& f, const std::vector<std::string>& methods);
Transform read_transform(const Fields& f);

// ---- The objects ----

uint32_t add_material(LoadState& st, Material m);
// The material "(default)", made on first use.
uint32_t default_material(LoadState& st);

// Refuses (InputError naming `path`, the count and the cap) a scene that would hold more
// than LoadLimits::max_triangles once `adding` more triangles are appended, or whose
// triangles would then need more than the memory budget at SCENE_TRIANGLE_BYTES each.
// Called before they are made.
void check_triangle_cap(const LoadState& st, const std::string& path, uint64_t adding);

// THE COUNT BEFORE THE BUILD (scene_count.cpp): the triangles the scene's `objects` will make
// (primitives by their type and segments, OBJ files by their face lines, glTF files by their
// accessors' counts and node instances) checked against the caps as check_triangle_cap does,
// before any is made: a scene over them is refused, naming the object that passes the cap,
// having built nothing. An object it cannot count (a malformed one) counts none: its own
// load refuses it.
void check_scene_triangles(const LoadState& st, const Json& objects);

// An OBJ file's triangles, from its face lines, without parsing (scene_mesh.cpp).
uint64_t count_face_triangles(const std::string& resolved);

// The canonical form of LoadLimits::root (InputError when it is not a folder).
std::string canonical_root(const std::string& root);
// Whether `file` (symbolic links and ".." resolved) lies inside the canonical `root`.
bool inside_root(const std::string& root, const std::string& file);
// Refuses `file` (as written at `path` of the scene) when it resolves outside the root.
void check_inside_root(const LoadState& st, const std::string& path, const std::string& file,
                       const std::string& resolved);

// A texture file named `file` at `path` of the scene (`where` prefixes the messages, see
// LoadState::texture_place), relative to `base_dir`: refused (InputError) when it resolves
// outside the root or is no readable regular file under MAX_TEXTURE_FILE_BYTES. Returns
// the resolved path and remembers where it was named for load_textures.
constexpr uint64_t MAX_TEXTURE_FILE_BYTES = uint64_t{256} << 20;  // 256 MiB
std::string texture_file(LoadState& st, const std::string& path, const std::string& where, const std::string& file,
                         const std::string& base_dir);

// Decodes every texture the materials name (files and SceneData::embedded_images) into
// SceneData::textures; an image that cannot be read or decoded is an InputError naming
// where the scene named it and why.
void load_textures(LoadState& st);
// A file path of the scene (absolute, or relative to its folder), made absolute or joined.
std::string resolve_mesh_path(const Source& src, const std::string& file);

// A mesh object's triangles from a Wavefront OBJ. With `use_mtl`, its MTL materials
// become scene materials named "FILE:NAME", and faces without one get the default.
LocalMesh read_obj(LoadState& st, const Fields& f, bool use_mtl);

// What a glTF file holds besides triangles, in the file's space (before the object's
// transform): KHR_lights_punctual point lights (colour already intensity / d^2, see
// scene_gltf.cpp) and the first perspective camera of its node hierarchy.
struct GltfExtras {
  std::vector<PointLight> lights;
  bool has_camera = false;
  glm::dvec3 camera_position{0.0}, camera_look_at{0.0}, camera_up{0.0};
  double camera_fov_y_deg = 60;
};

// A gltf object's triangles (scene_gltf.cpp): every triangle primitive of the file's scene,
// its node transforms applied. With `use_materials`, its materials become scene materials
// named "FILE:NAME" (primitives without one get the default); warnings for what is not
// rendered go to SceneData::warnings.
LocalMesh read_gltf(LoadState& st, const Fields& f, bool use_materials, GltfExtras* extras);

}  // namespace abcube::detail
