// gltf objects: glTF 2.0 files (.gltf with .bin files or data: URIs, and .glb) read through
// tinygltf (Debian's libtinygltf-dev, implementation in tiny_gltf_impl.cpp), flattened into
// one LocalMesh in the file's space: the node hierarchy, triangle primitives, materials,
// KHR_lights_punctual point lights and the first perspective camera. What is mapped and
// what is not is in docs/models-and-textures.md ("glTF 2.0").
//
// Before tinygltf sees the file, its JSON is checked (scene_gltf_schema.cpp): the version (2.x), the required
// extensions, the types of the members this loader uses (so that a number where an array
// belongs is an error naming its place, not a silently empty mesh) and every file it
// names (buffers and images: inside --root, regular files, under the caps). tinygltf then
// reads buffers through callbacks that check the same again; images are never decoded.
// The reader's parts: scene_gltf_reader.hpp.
#include <algorithm>
#include <cstring>
#include <filesystem>

#include "base/error.hpp"
#include "base/input_file.hpp"
#include "scene/scene_gltf_reader.hpp"

namespace abcube::detail {

namespace gltf {

namespace fs = std::filesystem;

namespace {

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

}  // namespace

LocalMesh GltfReader::read() {
  const std::string bytes = read_whole();
  const bool binary = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
  std::string json_text = bytes;
  if (binary) {
    GlbChunks glb = read_glb(bytes);
    if (!glb.problem.empty()) bad("", glb.problem);
    json_text = std::move(glb.json);
  }
  precheck(json_text);
  load(bytes, binary);
  convert();
  return std::move(out_);
}

std::string GltfReader::read_whole() const {
  std::string problem = input_file_problem(resolved_, st_.limits.max_mesh_bytes);
  if (!problem.empty()) bad("", "cannot read glTF " + quote_path(resolved_) + ": " + problem);
  return read_input_file(resolved_, st_.limits.max_mesh_bytes, "glTF");
}

std::string GltfReader::folder() const {
  const fs::path p = fs::path(resolved_).parent_path();
  return p.empty() ? "." : p.string();
}

std::string GltfReader::resolve_uri(const std::string& uri) const {
  const fs::path p(url_decode(uri));
  return (p.is_absolute() ? p : fs::path(folder()) / p).lexically_normal().string();
}

// ---- before tinygltf ----
void GltfReader::precheck(const std::string& json_text) {
  Json doc;
  try {
    doc = parse_document(json_text, Source{quote_path(file_), folder()});
  } catch (const InputError& e) {
    fail(st_.src, path_, e.what());
  }
  const auto bad_at = [&](const std::string& at, const std::string& what) { bad(at, what); };
  check_document(doc, bad_at,
                 [this](const Json& element, const std::string& at, bool buffer) { check_file(element, at, buffer); });
}

// A file a buffer or image names: inside the root, a regular file under the cap. A
// missing buffer is an error; a missing image loses its texture with a warning.
void GltfReader::check_file(const Json& element, const std::string& at, bool buffer) {
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

void GltfReader::load(const std::string& bytes, bool binary) {
  tg::TinyGLTF loader;
  FileRules rules{st_.root, st_.limits.max_mesh_bytes};
  loader.SetFsCallbacks(tg::FsCallbacks{fs_exists, fs_expand, fs_read, fs_write, &rules});
  loader.SetImageLoader(keep_image_bytes, nullptr);
  std::string err, warn;
  const bool ok =
      binary ? loader.LoadBinaryFromMemory(&model_, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                           static_cast<unsigned int>(bytes.size()), folder())
             : loader.LoadASCIIFromString(&model_, &err, &warn, bytes.data(), static_cast<unsigned int>(bytes.size()),
                                          folder());
  if (!ok) {
    std::string first = err.substr(0, err.find('\n'));
    if (first.empty()) first = "tinygltf could not read it";
    bad("", printable(first, 200));
  }
}

// ---- tinygltf's model -> LocalMesh ----
void GltfReader::convert() {
  if (!model_.animations.empty()) note("animations (the still pose is drawn)");
  std::vector<int> roots;
  if (model_.defaultScene >= 0 || !model_.scenes.empty()) {
    const int scene = std::max(model_.defaultScene, 0);
    if (static_cast<size_t>(scene) >= model_.scenes.size()) {
      bad("scene",
          "index " + std::to_string(scene) + " out of range (" + std::to_string(model_.scenes.size()) + " scenes)");
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
    st_.scene.warnings.push_back(
        one_line(st_.src.name + ": " + path_ + ": warning: glTF " + quote_path(file_) + ": not rendered: " + list));
  }
  if (!missing_images_.empty()) {
    st_.scene.warnings.push_back(one_line(st_.src.name + ": " + path_ + ": warning: glTF " + quote_path(file_) + ": " +
                                          *missing_images_.begin() + ".uri names no file; drawn untextured"));
  }
}

}  // namespace gltf

LocalMesh read_gltf(LoadState& st, const Fields& f, bool use_materials, GltfExtras* extras) {
  const std::string path = f.at("file");
  const std::string file = read_string(st.src, f.need("file"), path);
  if (file.empty()) fail(st.src, path, "must name a glTF file, got \"\"");
  const std::string resolved = resolve_mesh_path(st.src, file);
  check_inside_root(st, path, file, resolved);
  return gltf::GltfReader(st, path, file, resolved, use_materials, extras).read();
}

}  // namespace abcube::detail
