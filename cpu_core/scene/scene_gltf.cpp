// gltf objects: glTF 2.0 files (.gltf with .bin files or data: URIs, and .glb) read through
// tinygltf (Debian's libtinygltf-dev, implementation in tiny_gltf_impl.cpp), flattened into
// one LocalMesh in the file's space: the node hierarchy, triangle primitives, materials,
// KHR_lights_punctual point lights and the first perspective camera. What is mapped and
// what is not is in docs/models-and-textures.md ("glTF 2.0").
//
// Before tinygltf sees the file, its JSON is checked here: the version (2.x), the required
// extensions, the types of the members this loader uses (so that a number where an array
// belongs is an error naming its place, not a silently empty mesh) and every file it
// names (buffers and images: inside --root, regular files, under the caps). tinygltf then
// reads buffers through callbacks that check the same again; images are never decoded.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include "scene/tiny_gltf_config.hpp"

#include "base/error.hpp"
#include "base/input_file.hpp"
#include "scene/scene_load_state.hpp"

namespace abcube::detail {

namespace {

namespace tg = tinygltf;
namespace fs = std::filesystem;

// Percent-decoding of a URI (RFC 3986), as tinygltf decodes file URIs before it opens them.
std::string url_decode(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

bool is_data_uri(const std::string& uri) { return uri.rfind("data:", 0) == 0; }

// ---- File access for tinygltf: confined, capped, regular files only -------------------

struct FileRules {
  std::string root;  // canonical, or empty
  uint64_t max_bytes = 0;
};

bool fs_exists(const std::string& path, void*) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

std::string fs_expand(const std::string& path, void*) { return path; }  // no ~, no $VAR

bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  const FileRules& rules = *static_cast<const FileRules*>(user);
  if (!rules.root.empty() && !inside_root(rules.root, path)) {
    *err = "resolves outside --root " + rules.root;
    return false;
  }
  const std::string problem = input_file_problem(path, rules.max_bytes);
  if (!problem.empty()) {
    *err = problem;
    return false;
  }
  const std::string bytes = read_input_file(path, rules.max_bytes, "buffer");
  out->assign(bytes.begin(), bytes.end());
  return true;
}

bool fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  *err = "abcube writes no glTF";
  return false;
}

// Keeps an embedded image's encoded bytes (data: URI) for the samplers; nothing decoded.
bool keep_image_bytes(tg::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes,
                      int size, void*) {
  image->image.assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

// ---- The JSON before tinygltf: version, extensions, member types, files --------------

const std::set<std::string> SUPPORTED_REQUIRED = {"KHR_lights_punctual", "KHR_materials_transmission",
                                                  "KHR_materials_ior"};

enum class Kind { string, uint, number, boolean, object, array, uint_array, number_array, string_array, object_array };

const char* kind_name(Kind k) {
  switch (k) {
    case Kind::string: return "a string";
    case Kind::uint: return "an integer >= 0";
    case Kind::number: return "a number";
    case Kind::boolean: return "true or false";
    case Kind::object: return "an object";
    case Kind::array: return "an array";
    case Kind::uint_array: return "an array of integers >= 0";
    case Kind::number_array: return "an array of numbers";
    case Kind::string_array: return "an array of strings";
    case Kind::object_array: return "an array of objects";
  }
  return "";
}

bool is_uint(const Json& v) { return v.is_number_unsigned() || (v.is_number_integer() && v.get<int64_t>() >= 0); }

bool has_kind(const Json& v, Kind k) {
  const auto all = [&](bool (*ok)(const Json&)) { return v.is_array() && std::all_of(v.begin(), v.end(), ok); };
  switch (k) {
    case Kind::string: return v.is_string();
    case Kind::uint: return is_uint(v);
    case Kind::number: return v.is_number();
    case Kind::boolean: return v.is_boolean();
    case Kind::object: return v.is_object();
    case Kind::array: return v.is_array();
    case Kind::uint_array: return all(is_uint);
    case Kind::number_array: return all([](const Json& x) { return x.is_number(); });
    case Kind::string_array: return all([](const Json& x) { return x.is_string(); });
    case Kind::object_array: return all([](const Json& x) { return x.is_object(); });
  }
  return false;
}

struct Member {
  const char* key;
  Kind kind;
};

// The members this loader (or tinygltf for it) reads, by the array that holds them; every
// element also has "name" (a string) and "extensions" (an object).
const std::map<std::string, std::vector<Member>>& SCHEMA() {
  static const std::map<std::string, std::vector<Member>> schema = {
      {"accessors",
       {{"bufferView", Kind::uint}, {"byteOffset", Kind::uint}, {"componentType", Kind::uint},
        {"normalized", Kind::boolean}, {"count", Kind::uint}, {"type", Kind::string}, {"max", Kind::number_array},
        {"min", Kind::number_array}, {"sparse", Kind::object}}},
      {"animations", {}},
      {"buffers", {{"uri", Kind::string}, {"byteLength", Kind::uint}}},
      {"bufferViews",
       {{"buffer", Kind::uint}, {"byteOffset", Kind::uint}, {"byteLength", Kind::uint}, {"byteStride", Kind::uint},
        {"target", Kind::uint}}},
      {"cameras", {{"type", Kind::string}, {"perspective", Kind::object}, {"orthographic", Kind::object}}},
      {"images", {{"uri", Kind::string}, {"mimeType", Kind::string}, {"bufferView", Kind::uint}}},
      {"materials",
       {{"pbrMetallicRoughness", Kind::object}, {"emissiveFactor", Kind::number_array}, {"alphaMode", Kind::string},
        {"alphaCutoff", Kind::number}, {"doubleSided", Kind::boolean}}},
      {"meshes", {{"primitives", Kind::object_array}, {"weights", Kind::number_array}}},
      {"nodes",
       {{"camera", Kind::uint}, {"children", Kind::uint_array}, {"skin", Kind::uint}, {"matrix", Kind::number_array},
        {"mesh", Kind::uint}, {"rotation", Kind::number_array}, {"scale", Kind::number_array},
        {"translation", Kind::number_array}, {"weights", Kind::number_array}}},
      {"samplers", {}},
      {"scenes", {{"nodes", Kind::uint_array}}},
      {"skins", {}},
      {"textures", {{"sampler", Kind::uint}, {"source", Kind::uint}}},
  };
  return schema;
}

const std::vector<Member> PRIMITIVE = {{"attributes", Kind::object}, {"indices", Kind::uint},
                                       {"material", Kind::uint},     {"mode", Kind::uint},
                                       {"targets", Kind::object_array}, {"extensions", Kind::object}};

// Refuses a member of `o` (at `at`) whose type is not its kind; `required` ones must be there.
void check_members(const std::function<void(const std::string&, const std::string&)>& bad, const Json& o,
                   const std::string& at, const std::vector<Member>& members) {
  for (const Member& m : members) {
    const auto it = o.find(m.key);
    if (it != o.end() && !has_kind(*it, m.kind)) {
      bad(member_path(at, m.key), std::string("must be ") + kind_name(m.kind) + ", got " + describe(*it));
    }
  }
}

// Every "extensions" member anywhere in the document must be an object of objects.
void check_extensions(const std::function<void(const std::string&, const std::string&)>& bad, const Json& v,
                      const std::string& at) {
  if (v.is_array()) {
    for (size_t i = 0; i < v.size(); ++i) check_extensions(bad, v[i], index_path(at, i));
    return;
  }
  if (!v.is_object()) return;
  for (const auto& m : v.items()) {
    const std::string mat = member_path(at, m.key());
    if (m.key() == "extras") continue;  // anything the application likes
    if (m.key() == "extensions") {
      if (!m.value().is_object()) bad(mat, "must be an object, got " + describe(m.value()));
      for (const auto& e : m.value().items()) {
        if (!e.value().is_object()) bad(member_path(mat, e.key()), "must be an object, got " + describe(e.value()));
      }
    }
    check_extensions(bad, m.value(), mat);
  }
}

// A material's members and texture references (glTF 5.19 - 5.22).
void check_material(const std::function<void(const std::string&, const std::string&)>& bad, const Json& m,
                    const std::string& at) {
  const auto texture_info = [&](const Json& o, const std::string& key) {
    const auto it = o.find(key);
    if (it == o.end()) return;
    const std::string tat = member_path(at, key);
    check_members(bad, *it, tat, {{"index", Kind::uint}, {"texCoord", Kind::uint}, {"scale", Kind::number},
                                  {"strength", Kind::number}});
    if (!it->contains("index")) bad(member_path(tat, "index"), "missing required field");
  };
  check_members(bad, m, at, {{"normalTexture", Kind::object}, {"occlusionTexture", Kind::object},
                             {"emissiveTexture", Kind::object}});
  for (const char* key : {"normalTexture", "occlusionTexture", "emissiveTexture"}) texture_info(m, key);
  const auto pbr = m.find("pbrMetallicRoughness");
  if (pbr == m.end()) return;
  const std::string pat = member_path(at, "pbrMetallicRoughness");
  check_members(bad, *pbr, pat, {{"baseColorFactor", Kind::number_array}, {"baseColorTexture", Kind::object},
                                 {"metallicFactor", Kind::number}, {"roughnessFactor", Kind::number},
                                 {"metallicRoughnessTexture", Kind::object}});
  for (const char* key : {"baseColorTexture", "metallicRoughnessTexture"}) {
    const auto it = pbr->find(key);
    if (it == pbr->end()) continue;
    check_members(bad, *it, member_path(pat, key), {{"index", Kind::uint}, {"texCoord", Kind::uint}});
    if (!it->contains("index")) bad(member_path(member_path(pat, key), "index"), "missing required field");
  }
}

// The JSON chunk of a .glb (binary glTF, version 2), or "" when the container is not one
// (tinygltf then names what is wrong).
std::string glb_json(const std::string& bytes) {
  const auto u32 = [&](size_t at) {
    uint32_t v = 0;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  if (bytes.size() < 20 || bytes.compare(0, 4, "glTF") != 0 || u32(4) != 2) return "";
  const uint32_t length = u32(12);
  if (u32(16) != 0x4E4F534Au /* JSON */ || length > bytes.size() - 20) return "";
  return bytes.substr(20, length);
}

// ---- Reading accessors ---------------------------------------------------------------

int components(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
  }
}

const char* type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "unknown";
  }
}

const char* component_name(int c) {
  switch (c) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
    default: return "unknown";
  }
}

size_t component_bytes(int c) {
  switch (c) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

// One component at `p`, normalized integers mapped to [0, 1] or [-1, 1] (glTF 3.11).
double read_component(const unsigned char* p, int c, bool normalized) {
  switch (c) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const double v = static_cast<int8_t>(*p);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? *p / 255.0 : *p;
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

// What a primitive's attributes became.
struct Accessed {
  size_t count = 0;
  int n = 0;  // components per element
  std::vector<double> values;  // count * n
};

// How the triangles of a primitive are made from its vertex list.
const char* mode_name(int mode) {
  static const char* names[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP", "TRIANGLES", "TRIANGLE_STRIP", "TRIANGLE_FAN"};
  return mode >= 0 && mode <= 6 ? names[mode] : "unknown";
}

// A perspective camera found in the file, in the file's space.
struct FileCamera {
  glm::dvec3 position, look_at, up;
  double fov_y_deg = 60, aspect = 0;
};

class GltfReader {
 public:
  GltfReader(LoadState& st, const std::string& path, const std::string& file, const std::string& resolved,
             bool use_materials, GltfExtras* extras)
      : st_(st), path_(path), file_(file), resolved_(resolved), use_materials_(use_materials), extras_(extras) {}

  LocalMesh read() {
    const std::string bytes = read_whole();
    const bool binary = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
    if (binary && bytes.size() >= 8) {
      uint32_t version = 0;
      std::memcpy(&version, bytes.data() + 4, 4);
      if (version != 2) bad("", "binary glTF version " + std::to_string(version) + ": only glTF 2.0 is read");
    }
    const std::string json_text = binary ? glb_json(bytes) : bytes;
    if (!binary || !json_text.empty()) precheck(json_text);
    load(bytes, binary);
    convert();
    return std::move(out_);
  }

 private:
  // ---- messages ----
  [[noreturn]] void bad(const std::string& at, const std::string& what) const {
    fail(st_.src, path_, quote_path(file_) + ": " + (at.empty() ? "" : at + ": ") + what);
  }
  void note(const std::string& what) { ignored_.insert(what); }

  std::string read_whole() const {
    std::string problem = input_file_problem(resolved_, st_.limits.max_mesh_bytes);
    if (!problem.empty()) bad("", "cannot read glTF " + quote_path(resolved_) + ": " + problem);
    return read_input_file(resolved_, st_.limits.max_mesh_bytes, "glTF");
  }

  std::string folder() const {
    const fs::path p = fs::path(resolved_).parent_path();
    return p.empty() ? "." : p.string();
  }
  std::string resolve_uri(const std::string& uri) const {
    const fs::path p(url_decode(uri));
    return (p.is_absolute() ? p : fs::path(folder()) / p).lexically_normal().string();
  }

  // ---- before tinygltf ----
  void precheck(const std::string& json_text) {
    Json doc;
    try {
      doc = parse_document(json_text, Source{quote_path(file_), folder()});
    } catch (const InputError& e) {
      fail(st_.src, path_, e.what());
    }
    const auto bad_at = [&](const std::string& at, const std::string& what) { bad(at, what); };
    if (!doc.is_object()) bad("", "must hold a JSON object, got " + describe(doc));
    check_extensions(bad_at, doc, "");
    const auto asset = doc.find("asset");
    if (asset == doc.end() || !asset->is_object()) bad("asset", "missing (a glTF 2.0 file has asset.version \"2.0\")");
    const auto version = asset->find("version");
    if (version == asset->end() || !version->is_string() || version->get<std::string>().rfind("2.", 0) != 0) {
      bad("asset.version", "only glTF 2.0 is read, got " + (version == asset->end() ? std::string("nothing") : describe(*version)));
    }
    check_members(bad_at, doc, "", {{"scene", Kind::uint}, {"extensionsUsed", Kind::string_array},
                                    {"extensionsRequired", Kind::string_array}, {"extensions", Kind::object}});
    if (const auto req = doc.find("extensionsRequired"); req != doc.end()) {
      for (size_t i = 0; i < req->size(); ++i) {
        const std::string name = (*req)[i].get<std::string>();
        if (!SUPPORTED_REQUIRED.count(name)) {
          bad(index_path("extensionsRequired", i),
              quote(name) + " is not supported (supported: KHR_lights_punctual, KHR_materials_transmission, "
                            "KHR_materials_ior)");
        }
      }
    }
    for (const auto& [array, members] : SCHEMA()) {
      const auto it = doc.find(array);
      if (it == doc.end()) continue;
      if (!it->is_array()) bad(array, "must be an array, got " + describe(*it));
      for (size_t i = 0; i < it->size(); ++i) {
        const Json& element = (*it)[i];
        const std::string at = index_path(array, i);
        if (!element.is_object()) bad(at, "must be an object, got " + describe(element));
        check_members(bad_at, element, at, members);
        check_members(bad_at, element, at, {{"name", Kind::string}, {"extensions", Kind::object}});
        if (array == "meshes") {
          const auto prims = element.find("primitives");
          if (prims == element.end()) bad(at, "primitives: missing required field");
          for (size_t k = 0; k < prims->size(); ++k) {
            const std::string pat = index_path(member_path(at, "primitives"), k);
            check_members(bad_at, (*prims)[k], pat, PRIMITIVE);
            const auto attributes = (*prims)[k].find("attributes");
            if (attributes == (*prims)[k].end()) bad(pat, "attributes: missing required field");
            for (const auto& a : attributes->items()) {
              if (!is_uint(a.value())) {
                bad(member_path(member_path(pat, "attributes"), a.key()),
                    "must be an integer >= 0, got " + describe(a.value()));
              }
            }
          }
        }
        if (array == "buffers" || array == "images") check_file(element, at, array == "buffers");
        if (array == "materials") check_material(bad_at, element, at);
      }
    }
  }

  // A file a buffer or image names: inside the root, a regular file under the cap. A
  // missing buffer is an error; a missing image loses its texture with a warning.
  void check_file(const Json& element, const std::string& at, bool buffer) {
    const auto uri = element.find("uri");
    if (uri == element.end() || is_data_uri(uri->get<std::string>())) return;
    const std::string written = uri->get<std::string>();
    const std::string where = member_path(at, "uri") + " " + quote_path(written);
    const std::string resolved = resolve_uri(written);
    if (!st_.root.empty() && !inside_root(st_.root, resolved)) bad("", where + " resolves outside --root " + st_.root);
    std::error_code ec;
    if (!buffer && !fs::exists(resolved, ec)) {
      missing_images_.insert(at);
      return;
    }
    const std::string problem = input_file_problem(resolved, st_.limits.max_mesh_bytes);
    if (!problem.empty()) bad("", where + ": " + problem);
  }

  void load(const std::string& bytes, bool binary) {
    tg::TinyGLTF loader;
    FileRules rules{st_.root, st_.limits.max_mesh_bytes};
    loader.SetFsCallbacks(tg::FsCallbacks{fs_exists, fs_expand, fs_read, fs_write, &rules});
    loader.SetImageLoader(keep_image_bytes, nullptr);
    std::string err, warn;
    const bool ok = binary ? loader.LoadBinaryFromMemory(&model_, &err, &warn,
                                                          reinterpret_cast<const unsigned char*>(bytes.data()),
                                                          static_cast<unsigned int>(bytes.size()), folder())
                           : loader.LoadASCIIFromString(&model_, &err, &warn, bytes.data(),
                                                        static_cast<unsigned int>(bytes.size()), folder());
    if (!ok) {
      std::string first = err.substr(0, err.find('\n'));
      if (first.empty()) first = "tinygltf could not read it";
      bad("", printable(first, 200));
    }
  }

  // ---- tinygltf's model -> LocalMesh ----
  void convert() {
    if (!model_.animations.empty()) note("animations (the still pose is drawn)");
    std::vector<int> roots;
    if (model_.defaultScene >= 0 || !model_.scenes.empty()) {
      const int scene = std::max(model_.defaultScene, 0);
      if (static_cast<size_t>(scene) >= model_.scenes.size()) {
        bad("scene", "index " + std::to_string(scene) + " out of range (" + std::to_string(model_.scenes.size()) + " scenes)");
      }
      roots = model_.scenes[static_cast<size_t>(scene)].nodes;
    } else {
      // No scene: every node that is no other node's child (glTF 3.5.2 leaves this to us).
      std::vector<bool> child(model_.nodes.size(), false);
      for (const tg::Node& n : model_.nodes) {
        for (int c : n.children) {
          if (c >= 0 && static_cast<size_t>(c) < child.size()) child[static_cast<size_t>(c)] = true;
        }
      }
      for (size_t i = 0; i < child.size(); ++i) {
        if (!child[i]) roots.push_back(static_cast<int>(i));
      }
    }
    std::vector<bool> on_path(model_.nodes.size(), false);
    for (int r : roots) visit(r, glm::dmat4(1.0), "scenes nodes", &on_path);
    finish_lights();
    if (!ignored_.empty()) {
      std::string list;
      for (const std::string& s : ignored_) list += (list.empty() ? "" : "; ") + s;
      st_.scene.warnings.push_back(one_line(st_.src.name + ": " + path_ + ": warning: glTF " + quote_path(file_) +
                                            ": not rendered: " + list));
    }
    if (!missing_images_.empty()) {
      st_.scene.warnings.push_back(one_line(st_.src.name + ": " + path_ + ": warning: glTF " + quote_path(file_) + ": " +
                                            *missing_images_.begin() + ".uri names no file; drawn untextured"));
    }
  }

  glm::dmat4 local_matrix(const tg::Node& n, const std::string& at) const {
    const auto finite = [&](const std::vector<double>& v, const char* key, size_t size) {
      if (!v.empty() && v.size() != size) {
        bad(member_path(at, key), "must have " + std::to_string(size) + " numbers, got " + std::to_string(v.size()));
      }
      for (double x : v) {
        if (!std::isfinite(x)) bad(member_path(at, key), "must be finite");
      }
    };
    finite(n.matrix, "matrix", 16);
    finite(n.translation, "translation", 3);
    finite(n.rotation, "rotation", 4);
    finite(n.scale, "scale", 3);
    if (!n.matrix.empty()) {
      glm::dmat4 m;
      for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) m[c][r] = n.matrix[static_cast<size_t>(4 * c + r)];  // column-major
      }
      return m;
    }
    glm::dmat4 t(1.0), r(1.0), s(1.0);
    if (!n.translation.empty()) t[3] = glm::dvec4(n.translation[0], n.translation[1], n.translation[2], 1.0);
    if (!n.rotation.empty()) {
      glm::dquat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);  // glTF: x, y, z, w
      const double len = glm::length(q);
      if (!(len > 0)) bad(member_path(at, "rotation"), "must be a nonzero quaternion");
      r = glm::mat4_cast(q / len);
    }
    if (!n.scale.empty()) s = glm::scale(glm::dmat4(1.0), glm::dvec3(n.scale[0], n.scale[1], n.scale[2]));
    return t * r * s;
  }

  void visit(int index, const glm::dmat4& parent, const std::string& from, std::vector<bool>* on_path) {
    if (index < 0 || static_cast<size_t>(index) >= model_.nodes.size()) {
      bad(from, "node " + std::to_string(index) + " out of range (" + std::to_string(model_.nodes.size()) + " nodes)");
    }
    const std::string at = index_path("nodes", static_cast<size_t>(index));
    if ((*on_path)[static_cast<size_t>(index)]) bad(at, "is its own ancestor (the node hierarchy has a cycle)");
    if (++visits_ > MAX_NODE_VISITS) bad(at, "the node hierarchy instances more than " + std::to_string(MAX_NODE_VISITS) + " nodes");
    (*on_path)[static_cast<size_t>(index)] = true;
    const tg::Node& n = model_.nodes[static_cast<size_t>(index)];
    const glm::dmat4 world = parent * local_matrix(n, at);
    if (n.skin >= 0) note("skins (meshes drawn unskinned)");
    if (n.mesh >= 0) {
      if (static_cast<size_t>(n.mesh) >= model_.meshes.size()) {
        bad(member_path(at, "mesh"), "index " + std::to_string(n.mesh) + " out of range (" +
                                         std::to_string(model_.meshes.size()) + " meshes)");
      }
      const tg::Mesh& mesh = model_.meshes[static_cast<size_t>(n.mesh)];
      for (size_t p = 0; p < mesh.primitives.size(); ++p) {
        add_primitive(mesh.primitives[p], index_path(index_path("meshes", static_cast<size_t>(n.mesh)) + ".primitives", p),
                      world);
      }
    }
    if (n.camera >= 0) add_camera(n.camera, at, world);
    const auto light = n.extensions.find("KHR_lights_punctual");
    if (light != n.extensions.end() && light->second.Has("light")) add_light(light->second.Get("light"), at, world);
    for (int c : n.children) visit(c, world, member_path(at, "children"), on_path);
    (*on_path)[static_cast<size_t>(index)] = false;
  }

  // The accessor's elements as doubles (normalized integers mapped), checked against the
  // types allowed and against its buffer view and buffer.
  Accessed read_accessor(int index, const std::string& at, std::initializer_list<int> types,
                         std::initializer_list<int> component_types, bool allow_normalized_only = false) const {
    if (index < 0 || static_cast<size_t>(index) >= model_.accessors.size()) {
      bad(at, "accessor " + std::to_string(index) + " out of range (" + std::to_string(model_.accessors.size()) +
                  " accessors)");
    }
    const tg::Accessor& a = model_.accessors[static_cast<size_t>(index)];
    const std::string aat = at + " (accessors[" + std::to_string(index) + "])";
    if (std::find(types.begin(), types.end(), a.type) == types.end()) {
      std::string list;
      for (int t : types) list += std::string(list.empty() ? "" : " or ") + type_name(t);
      bad(aat, std::string("type ") + type_name(a.type) + ", expected " + list);
    }
    const bool float_ok = a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
    if (std::find(component_types.begin(), component_types.end(), a.componentType) == component_types.end() ||
        (allow_normalized_only && !float_ok && !a.normalized)) {
      std::string list;
      for (int c : component_types) list += std::string(list.empty() ? "" : ", ") + component_name(c);
      bad(aat, std::string("componentType ") + component_name(a.componentType) + (a.normalized ? " normalized" : "") +
                   ", expected " + list + (allow_normalized_only ? " (integers normalized)" : ""));
    }
    Accessed out;
    out.n = components(a.type);
    out.count = a.count;
    const size_t elem = component_bytes(a.componentType) * static_cast<size_t>(out.n);
    if (a.count > 3 * MAX_TRIANGLES) bad(aat, "count " + std::to_string(a.count) + " is more than this program holds");
    out.values.assign(a.count * static_cast<size_t>(out.n), 0.0);  // no bufferView: zeros (glTF 3.6.2.3)
    const auto view_bytes = [&](int view, size_t offset, size_t count, size_t element, size_t* stride,
                                const std::string& vat) -> const unsigned char* {
      if (view < 0 || static_cast<size_t>(view) >= model_.bufferViews.size()) {
        bad(vat, "bufferView " + std::to_string(view) + " out of range");
      }
      const tg::BufferView& bv = model_.bufferViews[static_cast<size_t>(view)];
      if (bv.buffer < 0 || static_cast<size_t>(bv.buffer) >= model_.buffers.size()) {
        bad(vat, "bufferViews[" + std::to_string(view) + "].buffer out of range");
      }
      const tg::Buffer& buf = model_.buffers[static_cast<size_t>(bv.buffer)];
      if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset) {
        bad(vat, "bufferViews[" + std::to_string(view) + "] runs past the end of its buffer (" +
                     std::to_string(buf.data.size()) + " bytes)");
      }
      *stride = bv.byteStride ? bv.byteStride : element;
      if (*stride < element) bad(vat, "byteStride " + std::to_string(*stride) + " is less than an element's bytes");
      if (count > 0 && (offset > bv.byteLength || (count - 1) > (bv.byteLength - offset) / *stride ||
                        (count - 1) * *stride + element > bv.byteLength - offset)) {
        bad(vat, std::to_string(count) + " elements run past the end of bufferViews[" + std::to_string(view) + "] (" +
                     std::to_string(bv.byteLength) + " bytes)");
      }
      return buf.data.data() + bv.byteOffset + offset;
    };
    if (a.bufferView >= 0) {
      size_t stride = 0;
      const unsigned char* p = view_bytes(a.bufferView, a.byteOffset, a.count, elem, &stride, aat);
      const size_t cb = component_bytes(a.componentType);
      for (size_t i = 0; i < a.count; ++i) {
        for (int k = 0; k < out.n; ++k) {
          out.values[i * static_cast<size_t>(out.n) + static_cast<size_t>(k)] =
              read_component(p + i * stride + static_cast<size_t>(k) * cb, a.componentType, a.normalized);
        }
      }
    }
    if (a.sparse.isSparse) {
      const size_t n = a.sparse.count < 0 ? 0 : static_cast<size_t>(a.sparse.count);
      const int ict = a.sparse.indices.componentType;
      if (ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
          ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
        bad(aat + ".sparse.indices", std::string("componentType ") + component_name(ict) + ", expected an unsigned integer");
      }
      size_t istride = 0, vstride = 0;
      const unsigned char* ip = view_bytes(a.sparse.indices.bufferView, static_cast<size_t>(std::max(0, a.sparse.indices.byteOffset)),
                                           n, component_bytes(ict), &istride, aat + ".sparse.indices");
      const unsigned char* vp = view_bytes(a.sparse.values.bufferView, static_cast<size_t>(std::max(0, a.sparse.values.byteOffset)),
                                           n, elem, &vstride, aat + ".sparse.values");
      istride = component_bytes(ict);  // sparse data is tightly packed
      vstride = elem;
      for (size_t i = 0; i < n; ++i) {
        const double target = read_component(ip + i * istride, ict, false);
        if (target >= static_cast<double>(a.count)) {
          bad(aat + ".sparse.indices", "index " + format_number(target) + " out of range (" + std::to_string(a.count) + " elements)");
        }
        for (int k = 0; k < out.n; ++k) {
          out.values[static_cast<size_t>(target) * static_cast<size_t>(out.n) + static_cast<size_t>(k)] =
              read_component(vp + i * vstride + static_cast<size_t>(k) * component_bytes(a.componentType), a.componentType,
                             a.normalized);
        }
      }
    }
    for (size_t i = 0; i < out.values.size(); ++i) {
      if (!std::isfinite(out.values[i])) {
        bad(aat, "element " + std::to_string(i / static_cast<size_t>(out.n)) + " is not finite (" +
                     format_number(out.values[i]) + ")");
      }
    }
    return out;
  }

  void add_primitive(const tg::Primitive& prim, const std::string& at, const glm::dmat4& world) {
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode > TINYGLTF_MODE_TRIANGLE_FAN) bad(member_path(at, "mode"), "must be 0 ... 6, got " + std::to_string(mode));
    if (mode < TINYGLTF_MODE_TRIANGLES) {
      note("points and lines (" + std::string(mode_name(mode)) + " primitives skipped)");
      return;
    }
    if (!prim.targets.empty()) note("morph targets (the base shape is drawn)");
    if (prim.extensions.count("KHR_draco_mesh_compression")) note("KHR_draco_mesh_compression (its uncompressed fallback is drawn)");
    const auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) {
      note("primitives without POSITION");
      return;
    }
    const std::string aat = member_path(at, "attributes");
    const Accessed p = read_accessor(pos->second, member_path(aat, "POSITION"), {TINYGLTF_TYPE_VEC3},
                                     {TINYGLTF_COMPONENT_TYPE_FLOAT});
    Accessed nrm;
    if (const auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
      nrm = read_accessor(it->second, member_path(aat, "NORMAL"), {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT});
      if (nrm.count != p.count) {
        bad(member_path(aat, "NORMAL"), std::to_string(nrm.count) + " elements, POSITION has " + std::to_string(p.count));
      }
    }
    const int material = material_of(prim.material, member_path(at, "material"));
    Accessed uv;
    const int set = texcoord_set(prim.material);
    if (set >= 0) {
      const std::string key = "TEXCOORD_" + std::to_string(set);
      if (const auto it = prim.attributes.find(key); it != prim.attributes.end()) {
        uv = read_accessor(it->second, member_path(aat, key.c_str()), {TINYGLTF_TYPE_VEC2},
                           {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                            TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                           true);
        if (uv.count != p.count) {
          bad(member_path(aat, key.c_str()), std::to_string(uv.count) + " elements, POSITION has " + std::to_string(p.count));
        }
      }
    }
    // The vertex list: the indices, or 0 ... count - 1.
    std::vector<uint32_t> list;
    if (prim.indices >= 0) {
      const std::string iat = member_path(at, "indices");
      const Accessed idx = read_accessor(prim.indices, iat, {TINYGLTF_TYPE_SCALAR},
                                         {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT});
      list.reserve(idx.count);
      for (double v : idx.values) {
        if (v >= static_cast<double>(p.count)) {
          bad(iat, "index " + format_number(v) + " out of range (" + std::to_string(p.count) + " vertices)");
        }
        list.push_back(static_cast<uint32_t>(v));
      }
    } else {
      for (size_t i = 0; i < p.count; ++i) list.push_back(static_cast<uint32_t>(i));
    }
    std::vector<std::array<uint32_t, 3>> tris;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (list.size() % 3 != 0) note("vertices left over after the last whole triangle");
      for (size_t i = 0; i + 2 < list.size(); i += 3) tris.push_back({list[i], list[i + 1], list[i + 2]});
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (size_t i = 0; i + 2 < list.size(); ++i) {
        tris.push_back(i % 2 == 0 ? std::array<uint32_t, 3>{list[i], list[i + 1], list[i + 2]}
                                  : std::array<uint32_t, 3>{list[i + 1], list[i], list[i + 2]});
      }
    } else {
      for (size_t i = 1; i + 1 < list.size(); ++i) tris.push_back({list[i], list[i + 1], list[0]});
    }
    check_triangle_cap(st_, path_, out_.triangle_count() + tris.size());
    if (st_.scene.triangles->triangle_count() + out_.triangle_count() + tris.size() > MAX_TRIANGLES) {
      bad("", "the scene would exceed " + std::to_string(MAX_TRIANGLES) + " triangles");
    }
    const glm::dmat3 linear(world);
    const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(linear));
    const bool mirrors = glm::determinant(linear) < 0;
    const bool with_uv = !uv.values.empty();
    if (with_uv && out_.uvs.empty()) out_.uvs.assign(out_.positions.size(), glm::dvec2(0.0));
    for (const auto& t : tris) {
      const uint32_t order[3] = {t[0], mirrors ? t[2] : t[1], mirrors ? t[1] : t[2]};
      for (uint32_t v : order) {
        const double* q = &p.values[3 * v];
        out_.positions.push_back(glm::dvec3(world * glm::dvec4(q[0], q[1], q[2], 1.0)));
        glm::dvec3 n(0.0);  // flat
        if (!nrm.values.empty()) {
          const double* m = &nrm.values[3 * v];
          n = normal_matrix * glm::dvec3(m[0], m[1], m[2]);
          const double len = glm::length(n);
          n = len > 0 && std::isfinite(len) ? n / len : glm::dvec3(0.0);
        }
        out_.normals.push_back(n);
        if (with_uv) {
          out_.uvs.emplace_back(uv.values[2 * v], 1.0 - uv.values[2 * v + 1]);  // glTF's v runs down
        } else if (!out_.uvs.empty()) {
          out_.uvs.emplace_back(0.0);
        }
      }
      out_.material.push_back(material);
    }
  }

  // ---- materials ----
  const tg::Material* material_at(int index) const {
    return index >= 0 && static_cast<size_t>(index) < model_.materials.size() ? &model_.materials[static_cast<size_t>(index)]
                                                                             : nullptr;
  }
  int texcoord_set(int material) const {
    const tg::Material* m = material_at(material);
    return m && m->pbrMetallicRoughness.baseColorTexture.index >= 0 ? m->pbrMetallicRoughness.baseColorTexture.texCoord : 0;
  }

  int material_of(int index, const std::string& at) {
    if (!use_materials_) return -1;  // the object's own
    if (index < 0) return static_cast<int>(default_material(st_));
    if (static_cast<size_t>(index) >= model_.materials.size()) {
      bad(at, "index " + std::to_string(index) + " out of range (" + std::to_string(model_.materials.size()) + " materials)");
    }
    const std::string key = resolved_ + '\n' + std::to_string(index);
    auto it = st_.mtl_materials.find(key);
    if (it == st_.mtl_materials.end()) it = st_.mtl_materials.emplace(key, add_material(st_, convert_material(index))).first;
    return static_cast<int>(it->second);
  }

  static double extension_number(const tg::ExtensionMap& ext, const char* name, const char* key, double fallback,
                                 bool* present = nullptr) {
    const auto it = ext.find(name);
    if (it == ext.end()) return fallback;
    if (present) *present = true;
    if (!it->second.Has(key) || !it->second.Get(key).IsNumber()) return fallback;
    return it->second.Get(key).GetNumberAsDouble();
  }

  Material convert_material(int index) {
    const tg::Material& g = model_.materials[static_cast<size_t>(index)];
    const std::string at = index_path("materials", static_cast<size_t>(index));
    Material m;
    m.name = file_ + ":" + (g.name.empty() ? at : g.name);
    const std::vector<double>& base = g.pbrMetallicRoughness.baseColorFactor;
    if (base.size() != 4) bad(at + ".pbrMetallicRoughness.baseColorFactor", "must have 4 numbers");
    for (int k = 0; k < 4; ++k) {
      if (!(base[static_cast<size_t>(k)] >= 0 && base[static_cast<size_t>(k)] <= 1)) {
        bad(at + ".pbrMetallicRoughness.baseColorFactor", "must be 4 numbers in [0, 1]");
      }
    }
    m.color = glm::dvec3(base[0], base[1], base[2]);
    const auto unit = [&](double x, const std::string& key) {
      if (!(x >= 0 && x <= 1)) bad(member_path(at, key.c_str()), "must be in [0, 1], got " + format_number(x));
      return x;
    };
    const double metallic = unit(g.pbrMetallicRoughness.metallicFactor, "pbrMetallicRoughness.metallicFactor");
    const double rough = unit(g.pbrMetallicRoughness.roughnessFactor, "pbrMetallicRoughness.roughnessFactor");
    const double transmission =
        unit(extension_number(g.extensions, "KHR_materials_transmission", "transmissionFactor", 0.0),
             "extensions.KHR_materials_transmission.transmissionFactor");
    bool has_ior = false;
    const double ior = extension_number(g.extensions, "KHR_materials_ior", "ior", 1.5, &has_ior);
    if (!std::isfinite(ior) || (ior < 1 && ior != 0)) {
      bad(at + ".extensions.KHR_materials_ior.ior", "must be >= 1 (or 0), got " + format_number(ior));
    }
    m.transmit = transmission * (1.0 - metallic);
    m.reflect = std::min(metallic * (1.0 - rough), 1.0 - m.transmit);
    m.diffuse = m.ambient = 1.0 - m.reflect - m.transmit;
    m.ior = (m.transmit > 0 || has_ior) && ior >= 1 ? ior : (m.transmit > 0 ? 1.5 : 1.0);
    m.specular = 0.5 * (1.0 - rough);
    m.shininess = std::clamp(2.0 / std::max(std::pow(rough, 4.0), 1e-6) - 2.0, 1.0, 1000.0);
    const std::string mode = g.alphaMode.empty() ? "OPAQUE" : g.alphaMode;
    if (mode == "BLEND") {
      m.opacity = base[3];
    } else if (mode == "MASK") {
      m.opacity = base[3] >= g.alphaCutoff ? 1.0 : 0.0;
      if (g.pbrMetallicRoughness.baseColorTexture.index >= 0) note("MASK by the texture's alpha (the factor's alpha decides)");
    } else if (mode != "OPAQUE") {
      bad(member_path(at, "alphaMode"), "must be OPAQUE, MASK or BLEND, got " + quote(mode));
    }
    for (size_t k = 0; k < g.emissiveFactor.size(); ++k) {
      if (g.emissiveFactor[k] > 0) note("emission (emissiveFactor)");
    }
    if (g.emissiveTexture.index >= 0) note("emission (emissiveTexture)");
    for (const auto& e : g.extensions) {
      if (e.first == "KHR_materials_transmission" || e.first == "KHR_materials_ior") continue;
      note(e.first == "KHR_materials_pbrSpecularGlossiness" ? e.first + " (its metallic-roughness values are used)"
                                                             : e.first);
    }
    const tg::TextureInfo& tex = g.pbrMetallicRoughness.baseColorTexture;
    if (tex.index >= 0) {
      if (tex.extensions.count("KHR_texture_transform")) note("KHR_texture_transform");
      m.texture = texture_name(tex.index, at + ".pbrMetallicRoughness.baseColorTexture.index");
    }
    return m;
  }

  // Material::texture for textures[index]: the image file, or "#embedded/I".
  std::string texture_name(int index, const std::string& at) {
    if (static_cast<size_t>(index) >= model_.textures.size()) {
      bad(at, "texture " + std::to_string(index) + " out of range (" + std::to_string(model_.textures.size()) + " textures)");
    }
    const int source = model_.textures[static_cast<size_t>(index)].source;
    if (source < 0) return "";  // an image only an extension names (KHR_texture_basisu, EXT_texture_webp)
    if (static_cast<size_t>(source) >= model_.images.size()) {
      bad(index_path("textures", static_cast<size_t>(index)) + ".source",
          "image " + std::to_string(source) + " out of range (" + std::to_string(model_.images.size()) + " images)");
    }
    const std::string iat = index_path("images", static_cast<size_t>(source));
    const auto known = image_texture_.find(source);
    if (known != image_texture_.end()) return known->second;
    const tg::Image& image = model_.images[static_cast<size_t>(source)];
    std::string name;
    if (image.bufferView >= 0) {
      if (static_cast<size_t>(image.bufferView) >= model_.bufferViews.size()) bad(iat, "bufferView out of range");
      const tg::BufferView& bv = model_.bufferViews[static_cast<size_t>(image.bufferView)];
      if (bv.buffer < 0 || static_cast<size_t>(bv.buffer) >= model_.buffers.size() ||
          bv.byteOffset > model_.buffers[static_cast<size_t>(bv.buffer)].data.size() ||
          bv.byteLength > model_.buffers[static_cast<size_t>(bv.buffer)].data.size() - bv.byteOffset) {
        bad(iat, "its bufferView runs past the end of its buffer");
      }
      const unsigned char* b = model_.buffers[static_cast<size_t>(bv.buffer)].data.data() + bv.byteOffset;
      name = embed(iat, image.mimeType, std::vector<unsigned char>(b, b + bv.byteLength));
    } else if (!image.image.empty()) {
      name = embed(iat, image.mimeType, image.image);  // a data: URI
    } else if (!image.uri.empty() && !missing_images_.count(iat)) {
      name = texture_file(st_, path_, quote_path(file_) + ": " + iat + ".uri ", url_decode(image.uri), folder());
    }
    image_texture_[source] = name;
    return name;
  }

  std::string embed(const std::string& at, const std::string& mime, std::vector<unsigned char> bytes) {
    EmbeddedImage e;
    e.name = file_ + ": " + at;
    e.mime_type = mime;
    e.bytes = std::make_shared<const std::vector<unsigned char>>(std::move(bytes));
    st_.scene.embedded_images.push_back(std::move(e));
    return "#embedded/" + std::to_string(st_.scene.embedded_images.size() - 1);
  }

  // ---- cameras and lights ----
  void add_camera(int index, const std::string& at, const glm::dmat4& world) {
    if (static_cast<size_t>(index) >= model_.cameras.size()) {
      bad(member_path(at, "camera"), "index " + std::to_string(index) + " out of range (" +
                                          std::to_string(model_.cameras.size()) + " cameras)");
    }
    const tg::Camera& c = model_.cameras[static_cast<size_t>(index)];
    if (c.type != "perspective") {
      note("orthographic cameras");
      return;
    }
    if (extras_->has_camera) return;  // the first one found
    const double yfov_deg = c.perspective.yfov * 180.0 / 3.14159265358979323846;
    if (!(yfov_deg > 0 && yfov_deg < 180)) {
      bad(index_path("cameras", static_cast<size_t>(index)) + ".perspective.yfov",
          "must be in (0, pi), got " + format_number(c.perspective.yfov));
    }
    const glm::dvec3 eye(world * glm::dvec4(0, 0, 0, 1));
    const glm::dvec3 forward = glm::dmat3(world) * glm::dvec3(0, 0, -1);
    const glm::dvec3 up = glm::dmat3(world) * glm::dvec3(0, 1, 0);
    if (!(glm::length(forward) > 0) || !(glm::length(glm::cross(forward, up)) > 0)) {
      bad(at, "its transform flattens the camera");
    }
    extras_->has_camera = true;
    extras_->camera_position = eye;
    extras_->camera_look_at = eye + glm::normalize(forward);
    extras_->camera_up = up;
    extras_->camera_fov_y_deg = yfov_deg;
  }

  void add_light(const tg::Value& v, const std::string& at, const glm::dmat4& world) {
    const std::string lat = at + ".extensions.KHR_lights_punctual.light";
    if (!v.IsInt() || v.GetNumberAsInt() < 0 || static_cast<size_t>(v.GetNumberAsInt()) >= model_.lights.size()) {
      bad(lat, "must index the file's KHR_lights_punctual lights (" + std::to_string(model_.lights.size()) + ")");
    }
    const tg::Light& l = model_.lights[static_cast<size_t>(v.GetNumberAsInt())];
    if (l.type != "point") {
      note("KHR_lights_punctual " + l.type + " lights");
      return;
    }
    glm::dvec3 color(1.0);
    if (l.color.size() == 3) color = glm::dvec3(l.color[0], l.color[1], l.color[2]);
    const glm::dvec3 c = color * l.intensity;
    if (!(c.x >= 0 && c.y >= 0 && c.z >= 0 && std::isfinite(c.x + c.y + c.z))) {
      bad(lat, "color times intensity must be finite and >= 0");
    }
    PointLight p;
    p.position = glm::dvec3(world * glm::dvec4(0, 0, 0, 1));
    p.color = c;
    lights_.push_back(p);
  }

  // Our lights do not fall off with distance: a glTF point light of I candela becomes the
  // colour I / d^2 (1 cd at 1 m gives 1), d its distance from the centre of the file's
  // triangles (the inverse square evaluated once, where the model is).
  void finish_lights() {
    Bounds b;
    for (const glm::dvec3& p : out_.positions) {
      if (std::isfinite(p.x + p.y + p.z)) b.extend(p);
    }
    const glm::dvec3 centre = b.empty() ? glm::dvec3(0.0) : 0.5 * (b.lo + b.hi);
    const double floor = b.empty() ? 1.0 : std::max(1e-3 * glm::length(b.hi - b.lo), 1e-12);
    for (PointLight l : lights_) {
      const double d = std::max(glm::length(l.position - centre), floor);
      l.color /= d * d;
      extras_->lights.push_back(l);
    }
  }

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

}  // namespace

LocalMesh read_gltf(LoadState& st, const Fields& f, bool use_materials, GltfExtras* extras) {
  const std::string path = f.at("file");
  const std::string file = read_string(st.src, f.need("file"), path);
  if (file.empty()) fail(st.src, path, "must name a glTF file, got \"\"");
  const std::string resolved = resolve_mesh_path(st.src, file);
  check_inside_root(st, path, file, resolved);
  return GltfReader(st, path, file, resolved, use_materials, extras).read();
}

}  // namespace abcube::detail
