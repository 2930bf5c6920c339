// The glTF reader's parts, shared by its files (scene_gltf.cpp reads and walks the file,
// scene_gltf_schema.cpp checks its JSON before tinygltf does, scene_gltf_geometry.cpp turns
// accessors and primitives into triangles, scene_gltf_materials.cpp maps materials, textures,
// cameras and lights). Internal to scene loading.
#pragma once
#include <array>
#include <cstddef>
#include <functional>
#include <initializer_list>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include "scene/tiny_gltf_config.hpp"

#include "base/error.hpp"
#include "scene/scene_load_state.hpp"

namespace abcube::detail::gltf {

namespace tg = tinygltf;

// ---- URIs ----

// Percent-decoding of a URI (RFC 3986), as tinygltf decodes file URIs before it opens them.
std::string url_decode(const std::string& s);
bool is_data_uri(const std::string& uri);

// ---- The JSON before tinygltf (scene_gltf_schema.cpp) ----

// Reports a problem at a place of the file ("meshes[0].primitives[1]"); never returns.
using BadAt = std::function<void(const std::string& at, const std::string& what)>;
// A buffer or image element's file checked by the reader (its root and caps).
using CheckFile = std::function<void(const Json& element, const std::string& at, bool buffer)>;

// The document checked: the version (2.x), the required extensions, the types of the members
// this loader uses (a number where an array belongs is an error naming its place), and each
// buffer and image element through `check_file`.
void check_document(const Json& doc, const BadAt& bad, const CheckFile& check_file);

// A .glb (binary glTF 2.0) container read: its JSON chunk, or what is wrong with its
// layout. Every chunk lies wholly inside the header's length, so what tinygltf later takes
// from the BIN chunk is inside the file.
struct GlbChunks {
  std::string json;
  std::string problem;  // empty when the layout holds
};
GlbChunks read_glb(const std::string& bytes);

// ---- Accessors (scene_gltf_geometry.cpp) ----

int components(int type);
const char* type_name(int type);
const char* component_name(int c);
size_t component_bytes(int c);
// One component at `p`, normalized integers mapped to [0, 1] or [-1, 1] (glTF 3.11).
double read_component(const unsigned char* p, int c, bool normalized);

// What a primitive's attributes became.
struct Accessed {
  size_t count = 0;
  int n = 0;                   // components per element
  std::vector<double> values;  // count * n
};

// How the triangles of a primitive are made from its vertex list.
const char* mode_name(int mode);

// A perspective camera found in the file, in the file's space.
struct FileCamera {
  glm::dvec3 position, look_at, up;
  double fov_y_deg = 60, aspect = 0;
};

// Reads one gltf object's file into a LocalMesh (read_gltf, scene_load_state.hpp).
class GltfReader {
 public:
  GltfReader(LoadState& st, const std::string& path, const std::string& file, const std::string& resolved,
             bool use_materials, GltfExtras* extras)
      : st_(st), path_(path), file_(file), resolved_(resolved), use_materials_(use_materials), extras_(extras) {}

  LocalMesh read();

 private:
  // ---- messages ----
  [[noreturn]] void bad(const std::string& at, const std::string& what) const {
    fail(st_.src, path_, quote_path(file_) + ": " + (at.empty() ? "" : at + ": ") + what);
  }
  void note(const std::string& what) { ignored_.insert(what); }

  std::string read_whole() const;

  std::string folder() const;
  std::string resolve_uri(const std::string& uri) const;

  // ---- before tinygltf ----
  void precheck(const std::string& json_text);

  // A file a buffer or image names: inside the root, a regular file under the cap. A
  // missing buffer is an error; a missing image loses its texture with a warning.
  void check_file(const Json& element, const std::string& at, bool buffer);

  void load(const std::string& bytes, bool binary);

  // ---- tinygltf's model -> LocalMesh ----
  void convert();

  glm::dmat4 local_matrix(const tg::Node& n, const std::string& at) const;

  void visit(int index, const glm::dmat4& parent, const std::string& from, std::vector<bool>* on_path);

  // The accessor's elements as doubles (normalized integers mapped), checked against the
  // types allowed and against its buffer view and buffer.
  const unsigned char* view_bytes(int view, size_t offset, size_t count, size_t element, size_t* stride,
                                  const std::string& vat) const;
  void apply_sparse(const tg::Accessor& a, const std::string& aat, size_t elem, Accessed* accessed) const;
  Accessed read_accessor(int index, const std::string& at, std::initializer_list<int> types,
                         std::initializer_list<int> component_types, bool allow_normalized_only = false) const;

  void add_primitive(const tg::Primitive& prim, const std::string& at, const glm::dmat4& world);
  // The primitive's triangles as vertex indices (its indices or 0 ... count - 1, assembled
  // by `mode`: triangles, strip or fan).
  std::vector<std::array<uint32_t, 3>> primitive_triangles(const tg::Primitive& prim, const std::string& at, int mode,
                                                           size_t count);
  // The triangles' vertices, transformed by `world`, appended to the mesh.
  void append_triangles(const std::vector<std::array<uint32_t, 3>>& tris, const Accessed& positions,
                        const Accessed& normals, const Accessed& uvs, int material, const glm::dmat4& world);

  // ---- materials ----
  const tg::Material* material_at(int index) const;
  int texcoord_set(int material) const;

  int material_of(int index, const std::string& at);

  static double extension_number(const tg::ExtensionMap& ext, const char* name, const char* key, double fallback,
                                 bool* present = nullptr);

  Material convert_material(int index);

  // Material::texture for textures[index]: the image file, or "#embedded/I".
  std::string texture_name(int index, const std::string& at);

  std::string embed(const std::string& at, const std::string& mime, std::vector<unsigned char> bytes);

  // ---- cameras and lights ----
  void add_camera(int index, const std::string& at, const glm::dmat4& world);

  void add_light(const tg::Value& v, const std::string& at, const glm::dmat4& world);

  // Our lights do not fall off with distance: a glTF point light of I candela becomes the
  // colour I / d^2 (1 cd at 1 m gives 1), d its distance from the centre of the file's
  // triangles (the inverse square evaluated once, where the model is).
  void finish_lights();

  static constexpr size_t MAX_NODE_VISITS = size_t{1} << 20;

  LoadState& st_;
  const std::string& path_;
  const std::string file_, resolved_;
  const bool use_materials_;
  GltfExtras* extras_;
  tg::Model model_;
  LocalMesh out_;
  std::set<std::string> ignored_, missing_images_;
  std::map<int, std::string> image_texture_;
  std::vector<PointLight> lights_;
  size_t visits_ = 0;
};

}  // namespace abcube::detail::gltf
