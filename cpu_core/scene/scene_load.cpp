// Scene file (docs/scene-format.md, version 1) -> SceneData. Every value is checked where it is
// read, and every message names its place: "FILE:LINE:COL: ..." for JSON syntax (from the
// parser's byte offset, as nori does), "FILE: objects[3].radius: ..." for values.
//
// Required: version (= 1), camera.position, camera.look_at, objects, and per object its
// type and geometry (vertices; min, max; center, radius; file). Everything else has a
// default: camera up [0,1,0], fov_y 60, width and height 512; background [0,0,0];
// ambient [0.1,0.1,0.1]; no lights, no materials; light colour [1,1,1]; the material
// defaults of the format; sphere segments 32; an object without "material" gets the
// default material "(default)".
#include "scene/scene_load.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "base/error.hpp"
#include "base/input_file.hpp"
#include "base/memory.hpp"
#include "scene/framing.hpp"
#include "scene/radiance.hpp"
#include "scene/scene_load_state.hpp"
#include "scene/tessellate.hpp"

namespace abcube {

namespace detail {

uint32_t add_material(LoadState& st, Material m) {
  st.scene.materials.push_back(std::move(m));
  return static_cast<uint32_t>(st.scene.materials.size() - 1);
}

uint32_t default_material(LoadState& st) {
  if (st.default_material < 0) {
    Material m;
    m.name = DEFAULT_MATERIAL;
    st.default_material = static_cast<int>(add_material(st, m));
  }
  return static_cast<uint32_t>(st.default_material);
}

void check_triangle_cap(const LoadState& st, const std::string& path, uint64_t adding) {
  const uint64_t cap = st.limits.max_triangles;
  const uint64_t total = st.scene.triangles->triangle_count() + adding;
  if (cap > 0 && total > cap) {
    fail(st.src, path,
         "the scene would have " + std::to_string(total) + " triangles, over the cap of " + std::to_string(cap) +
             " (max_triangles)");
  }
  if (st.memory_budget > 0 && total > st.memory_budget / SCENE_TRIANGLE_BYTES) {
    const uint64_t mib = (total * SCENE_TRIANGLE_BYTES + (uint64_t{1} << 20) - 1) >> 20;
    fail(st.src, path,
         "the scene would have " + std::to_string(total) + " triangles, an estimated " + std::to_string(mib) +
             " MiB at " + std::to_string(SCENE_TRIANGLE_BYTES) + " bytes each, " +
             budget_words(st.memory_budget, st.limits.max_memory_mib > 0));
  }
}

}  // namespace detail

namespace {

using namespace detail;

constexpr int MIN_SEGMENTS = 3, MAX_SEGMENTS = 4096;
constexpr double MAX_QUAD_PLANARITY_ERROR = 1e-6;  // relative to the quad's diagonal

std::vector<glm::dvec3> read_points(const Fields& f, const char* key, size_t count) {
  const Json& v = f.need(key);
  if (!v.is_array() || v.size() != count) {
    fail(f.src(), f.at(key), "must be an array of " + std::to_string(count) + " points [x, y, z], got " + describe(v));
  }
  std::vector<glm::dvec3> points;
  for (size_t i = 0; i < count; ++i) points.push_back(read_vec3(f.src(), v[i], index_path(f.at(key), i)));
  return points;
}

LocalMesh read_quad(const Fields& f) {
  const std::vector<glm::dvec3> p = read_points(f, "vertices", 4);
  const std::array<glm::dvec3, 4> q = {p[0], p[1], p[2], p[3]};
  const double off_plane = quad_planarity_error(q);
  if (off_plane > MAX_QUAD_PLANARITY_ERROR) {
    char share[32];
    std::snprintf(share, sizeof share, "%.2g", off_plane);
    fail(f.src(), f.at("vertices"),
         std::string("the 4 vertices must be coplanar, got one off their plane by ") + share + " of the quad's size");
  }
  LocalMesh m;
  if (!tessellate_quad(q, &m)) {
    fail(f.src(), f.at("vertices"), "the quad crosses itself; give its 4 vertices in order around its edge");
  }
  return m;
}

LocalMesh read_box(const Fields& f) {
  const glm::dvec3 lo = f.vec3("min"), hi = f.vec3("max");
  for (int i = 0; i < 3; ++i) {
    if (!(lo[i] < hi[i])) {
      fail(f.src(), index_path(f.at("max"), static_cast<size_t>(i)),
           "must be > min[" + std::to_string(i) + "] = " + format_number(lo[i]) + ", got " + format_number(hi[i]));
    }
  }
  return tessellate_box(lo, hi);
}

LocalMesh read_sphere(const LoadState& st, const Fields& f) {
  const size_t triangles_so_far = st.scene.triangles->triangle_count();
  const glm::dvec3 center = f.vec3("center");
  const double radius = f.number("radius");
  if (!(radius > 0)) fail(f.src(), f.at("radius"), "must be > 0, got " + format_number(radius));
  const int segments = f.integer("segments", 32, MIN_SEGMENTS, MAX_SEGMENTS);
  if (triangles_so_far + sphere_triangle_count(segments) > MAX_TRIANGLES) {
    fail(f.src(), f.at("segments"),
         "the scene would exceed " + std::to_string(MAX_TRIANGLES) + " triangles, got " + std::to_string(segments));
  }
  check_triangle_cap(st, f.at("segments"), sphere_triangle_count(segments));
  return tessellate_sphere(center, radius, segments);
}

// Triangles of one object in object space, by type.
LocalMesh read_geometry(LoadState& st, const Fields& f, const std::string& type, bool has_material,
                        GltfExtras* extras) {
  if (type == "triangle") {
    const std::vector<glm::dvec3> p = read_points(f, "vertices", 3);
    return tessellate_triangle(p[0], p[1], p[2]);
  }
  if (type == "quad") return read_quad(f);
  if (type == "box") return read_box(f);
  if (type == "sphere") return read_sphere(st, f);
  if (type == "gltf") return read_gltf(st, f, !has_material, extras);
  return read_obj(st, f, !has_material);
}

// Whether an object of material `material` (or per-triangle `per_face` ones, -1 for its
// own) samples a texture anywhere.
bool uses_texture(const SceneData& scene, uint32_t material, const std::vector<int>& per_face) {
  const auto textured = [&](uint32_t m) { return m < scene.materials.size() && !scene.materials[m].texture.empty(); };
  if (per_face.empty()) return textured(material);
  std::vector<bool> seen(scene.materials.size() + 1, false);
  for (const int m : per_face) {
    const uint32_t id = m < 0 ? material : static_cast<uint32_t>(m);
    if (id < seen.size() && seen[id]) continue;
    if (textured(id)) return true;
    if (id < seen.size()) seen[id] = true;
  }
  return false;
}

// The fields an object of `type` may have (a located InputError for an unknown type).
std::vector<const char*> object_fields(const LoadState& st, const Json& type_value, const std::string& type,
                                       const std::string& path) {
  if (type == "triangle" || type == "quad") return {"type", "vertices", "material", "transform"};
  if (type == "box") return {"type", "min", "max", "material", "transform"};
  if (type == "sphere") return {"type", "center", "radius", "segments", "material", "transform"};
  if (type == "mesh") return {"type", "file", "material", "transform"};
  if (type == "gltf") return {"type", "file", "material", "transform", "use_camera"};
  fail(st.src, member_path(path, "type"),
       "must be one of triangle, quad, box, sphere, mesh, gltf, got " + describe(type_value));
}

// A glTF file's lights, placed by the object's transform, and its camera when the object
// asks for it and no other was given.
void add_extras(LoadState& st, const GltfExtras& extras, const AffineMap& map, bool use_camera) {
  for (PointLight light : extras.lights) {
    light.position = map.point(light.position);
    st.scene.lights.push_back(light);
  }
  if (use_camera && extras.has_camera && !st.file_camera) {
    Camera c;
    c.position = map.point(extras.camera_position);
    c.look_at = map.point(extras.camera_look_at);
    c.up = map.linear * extras.camera_up;
    c.fov_y_deg = extras.camera_fov_y_deg;
    st.file_camera = c;
  }
}

// An object with no triangles loads and renders (nothing), but an empty export, a wrong
// file or a mistyped vertex is the likely cause: a warning says so.
void warn_empty(LoadState& st, const Fields& f, const std::string& type, const std::string& path, size_t faces) {
  const bool named_file = type == "mesh" || type == "gltf";
  const std::string what =
      named_file ? (type == "gltf" ? "glTF " : "mesh ") + quote_path(read_string(st.src, f.need("file"), f.at("file")))
                 : type;
  st.scene.warnings.push_back(one_line(st.src.name + ": " + (named_file ? f.at("file") : path) + ": warning: " + what +
                                       " has no triangles" +
                                       (faces > 0 ? " of nonzero area (" + std::to_string(faces) + " dropped)" : "")));
}

void read_object(LoadState& st, const Json& v, size_t index) {
  const std::string path = index_path("objects", index);
  if (!v.is_object()) fail(st.src, path, "must be an object, got " + describe(v));
  const auto type_it = v.find("type");
  if (type_it == v.end()) fail(st.src, member_path(path, "type"), "missing required field");
  const std::string type = read_string(st.src, *type_it, member_path(path, "type"));
  const Fields f(st.src, v, path, object_fields(st, *type_it, type, path));

  SceneObject obj;
  obj.type = type;
  obj.path = path;
  const Json* material = f.find("material");
  if (material) {
    const std::string name = read_string(st.src, *material, f.at("material"));
    const auto it = st.material_by_name.find(name);
    if (it == st.material_by_name.end()) {
      fail(st.src, f.at("material"), "no material of that name in \"materials\", got " + describe(*material));
    }
    obj.material = it->second;
  }
  Transform transform;
  if (const Json* t = f.find("transform")) {
    transform = read_transform(Fields(st.src, *t, f.at("transform"), {"translate", "rotate_deg", "scale"}));
  }
  GltfExtras extras;
  const bool use_camera = f.find("use_camera") && read_bool(st.src, *f.find("use_camera"), f.at("use_camera"));
  LocalMesh local = read_geometry(st, f, type, material != nullptr, &extras);
  // Without a "material", a primitive gets the default and a mesh its per-face MTL ones.
  if (!material && local.material.empty()) obj.material = default_material(st);
  // Texture coordinates are kept only where a texture is sampled: untextured scenes keep
  // the soup without them (memory, and the GL vertex buffer).
  if (!uses_texture(st.scene, obj.material, local.material)) {
    local.uvs = {};
    local.uv_index = {};
  }
  if (st.scene.triangles->triangle_count() + local.triangle_count() > MAX_TRIANGLES) {
    fail(st.src, path, "the scene would exceed " + std::to_string(MAX_TRIANGLES) + " triangles");
  }
  check_triangle_cap(st, path, local.triangle_count());
  const size_t faces = local.triangle_count();

  TriangleSoup& soup = st.scene.triangles.edit();
  const uint32_t id = static_cast<uint32_t>(st.scene.objects.size());
  obj.first_triangle = static_cast<uint32_t>(soup.triangle_count());
  const AffineMap map = make_affine_map(transform);
  st.scene.dropped_triangles += append_triangles(local, map, id, obj.material, &soup, st.limits.threads);
  add_extras(st, extras, map, use_camera);
  obj.triangle_count = static_cast<uint32_t>(soup.triangle_count() - obj.first_triangle);
  const bool per_face_materials = !local.material.empty();
  const bool from_file = local.indexed;
  local = LocalMesh{};                   // freed before the closed-surface test: peak memory
  if (from_file) release_free_memory();  // the OBJ parser's many small blocks
  if (!material && per_face_materials) {
    obj.material = obj.triangle_count > 0 ? soup.material_id[obj.first_triangle] : default_material(st);
  }
  if (obj.triangle_count == 0) warn_empty(st, f, type, path, faces);
  // A closed surface has an inside; make its geometric normals point out of it.
  obj.closed = is_closed_surface(soup, obj.first_triangle, obj.triangle_count);
  if (obj.closed && signed_volume(soup, obj.first_triangle, obj.triangle_count) < 0) {
    flip_winding(&soup, obj.first_triangle, obj.triangle_count);
  }
  st.scene.objects.push_back(std::move(obj));
}

void read_materials(LoadState& st, const Json& v) {
  if (!v.is_object()) fail(st.src, "materials", "must be an object of named materials, got " + describe(v));
  for (const auto& entry : v.items()) {
    const std::string path = member_path("materials", entry.key());
    if (entry.key().empty()) fail(st.src, path, "a material name must not be empty");
    const Fields f(
        st.src, entry.value(), path,
        {"color", "ambient", "diffuse", "specular", "shininess", "reflect", "transmit", "ior", "opacity", "texture"});
    Material m = read_material(f, entry.key());
    if (const Json* t = f.find("texture")) {
      m.texture = texture_file(st, f.at("texture"), "", read_string(st.src, *t, f.at("texture")), st.src.base_dir);
    }
    st.material_by_name[entry.key()] = add_material(st, std::move(m));
  }
}

const Json& read_array(const Source& src, const Json& v, const std::string& path) {
  if (!v.is_array()) fail(src, path, "must be an array, got " + describe(v));
  return v;
}

SceneData read_scene(const Json& doc, const Source& src, const LoadLimits& limits, const std::string& root) {
  const Fields top(src, doc, "",
                   {"version", "camera", "background", "ambient", "lights", "materials", "objects", "render"});
  const Json& version = top.need("version");
  if (!version.is_number() || version.get<double>() != 1.0) {
    fail(src, "version", "must be 1 (the only version this program reads), got " + describe(version));
  }
  SceneData scene;
  scene.file = src.name;
  const CameraSection camera =
      read_camera(Fields(src, top.need("camera"), "camera",
                         {"position", "look_at", "up", "fov_y", "width", "height", "frame", "direction"}));
  scene.camera = camera.camera;
  scene.background = top.vec3("background", scene.background);
  check_non_negative(src, "background", scene.background);
  scene.ambient = top.vec3("ambient", scene.ambient);
  check_non_negative(src, "ambient", scene.ambient);
  if (const Json* lights = top.find("lights")) {
    const Json& list = read_array(src, *lights, "lights");
    for (size_t i = 0; i < list.size(); ++i) {
      scene.lights.push_back(
          read_light(Fields(src, list[i], index_path("lights", i), {"type", "position", "color", "cast_shadows"})));
    }
  }
  LoadState st{src, scene, limits, root, {}, {}, -1, {}, {}, memory_budget_bytes(limits.max_memory_bytes())};
  if (const Json* materials = top.find("materials")) read_materials(st, *materials);
  const Json& objects = read_array(src, top.need("objects"), "objects");
  check_scene_triangles(st, objects);
  for (size_t i = 0; i < objects.size(); ++i) read_object(st, objects[i], i);
  if (camera.frame) {
    scene.camera = frame_camera(scene.bounds(), camera.direction, scene.camera);
    scene.frame_direction = camera.direction;
    // A framed scene without lights of its own (no "lights", none in its glTF files) is lit
    // from the frame; an explicit "lights": [] stays dark.
    if (scene.lights.empty() && !top.find("lights")) scene.lights = frame_lights(scene.bounds(), scene.camera);
  }
  if (st.file_camera) {  // a gltf object's "use_camera": its first perspective camera
    const Camera& c = *st.file_camera;
    scene.frame_direction.reset();
    scene.camera.position = c.position;
    scene.camera.look_at = c.look_at;
    scene.camera.up = c.up;
    scene.camera.fov_y_deg = c.fov_y_deg;
  }
  if (const Json* render = top.find("render")) {
    scene.render = read_render(
        Fields(src, *render, "render",
               {"method", "cube_resolution", "max_depth", "fresnel", "error_target", "target_db", "samples"}),
        st.limits.methods);
  }
  load_textures(st);
  check_radiance(scene, scene.render.max_depth, src.name + ": ");  // THE RADIANCE BOUND
  // The loaders' small blocks freed since the last object's trim (the closed-surface test's,
  // the JSON's): left resident, they would be carried by every method through its peak
  // (bench/memory.py measures it).
  if (scene.triangles->triangle_count() > 0) release_free_memory();
  return scene;
}

}  // namespace

SceneData load_scene_text(const std::string& text, const std::string& name, const std::string& base_dir) {
  return load_scene_text(text, name, base_dir, LoadLimits{});
}

namespace {

// One step of an override's path: a member name, or an index when `is_index`.
struct PathStep {
  std::string name;
  size_t index = 0;
  bool is_index = false;
};

// "materials[\"my glass\"].ior" -> materials, my glass, ior; "lights[0].position" -> lights, 0, position.
std::vector<PathStep> parse_override_path(const Source& src, const std::string& path) {
  const auto bad = [&](const std::string& why) { fail(src, path, "cannot set: " + why); };
  std::vector<PathStep> steps;
  size_t i = 0;
  while (i < path.size()) {
    if (path[i] == '[') {
      const size_t close = path.find(']', i);
      if (close == std::string::npos) bad("a '[' without its ']'");
      const std::string inside = path.substr(i + 1, close - i - 1);
      if (inside.size() >= 2 && inside.front() == '"' && inside.back() == '"') {
        steps.push_back({inside.substr(1, inside.size() - 2), 0, false});
      } else if (!inside.empty() && inside.size() <= 9 && inside.find_first_not_of("0123456789") == std::string::npos) {
        steps.push_back({"", static_cast<size_t>(std::stoul(inside)), true});
      } else {
        bad("[" + inside + "] is neither an index nor a quoted name");
      }
      i = close + 1;
      if (i < path.size() && path[i] == '.') ++i;
      continue;
    }
    const size_t end = path.find_first_of(".[", i);
    const std::string name = path.substr(i, end == std::string::npos ? std::string::npos : end - i);
    if (name.empty()) bad("an empty name");
    steps.push_back({name, 0, false});
    i = end == std::string::npos ? path.size() : (path[end] == '.' ? end + 1 : end);
  }
  if (steps.empty()) bad("an empty path");
  return steps;
}

// The document with each override in place (see SceneOverride).
void apply_overrides(Json& doc, const Source& src, const SceneOverrides& set) {
  for (const SceneOverride& o : set) {
    const std::vector<PathStep> steps = parse_override_path(src, o.path);
    Json* at = &doc;
    std::string where;
    for (const PathStep& step : steps) {
      if (step.is_index) {
        if (!at->is_array()) fail(src, where, "is not an array: cannot set " + o.path);
        if (step.index >= at->size()) {
          fail(src, index_path(where, step.index),
               "no such element (" + where + " has " + std::to_string(at->size()) + "): cannot set " + o.path);
        }
        at = &(*at)[step.index];
        where = index_path(where, step.index);
      } else {
        if (at->is_null()) *at = Json::object();
        if (!at->is_object()) fail(src, where, "is not an object: cannot set " + o.path);
        at = &(*at)[step.name];
        where = member_path(where, step.name);
      }
    }
    try {
      *at = Json::parse(o.value);
    } catch (const Json::exception&) {
      fail(src, o.path, "the value to set is not JSON, got " + quote(o.value));
    }
  }
}

}  // namespace

SceneData load_scene_text(const std::string& text, const std::string& name, const std::string& base_dir,
                          const LoadLimits& limits, const SceneOverrides& set) {
  const Source src{name, base_dir.empty() ? "." : base_dir};
  const std::string root = limits.root.empty() ? "" : canonical_root(limits.root);
  Json doc = parse_document(text, src);
  apply_overrides(doc, src, set);
  return read_scene(doc, src, limits, root);
}

SceneData load_scene(const std::string& path) { return load_scene(path, LoadLimits{}); }

namespace {

// The model file's kind by its extension (any case): "gltf", "mesh" or "" (a scene file).
std::string model_kind(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".gltf" || ext == ".glb") return "gltf";
  if (ext == ".obj") return "mesh";
  return "";
}

// A model file given where a scene is expected: the scene of that one model, framed, lit from
// the frame, 640 x 480 (docs/models-and-textures.md "A model file as the scene"). Messages name
// the model file itself ("box.gltf: meshes[0]...") rather than the scene made for it.
SceneData load_model_as_scene(const std::string& path, const std::string& kind, const LoadLimits& limits,
                              const SceneOverrides& set) {
  namespace fs = std::filesystem;
  const std::string file = fs::path(path).filename().string();
  Json object = {{"type", kind}, {"file", file}};
  if (kind == "gltf") object["use_camera"] = true;
  const Json doc = {{"version", 1},
                    {"camera", {{"frame", "all"}, {"width", 640}, {"height", 480}}},
                    {"objects", Json::array({object})}};
  const std::string dir = fs::path(path).parent_path().string();
  const std::string ours = path + ": objects[0].file: ", theirs = path + ": ";
  const auto rename = [&](std::string m) {
    if (m.rfind(ours, 0) == 0) m = theirs + m.substr(ours.size());
    // The loaders name their file again: the glTF one as written, the OBJ one resolved.
    const std::string resolved = quote_path((fs::path(dir.empty() ? "." : dir) / file).lexically_normal().string());
    for (const std::string& again : {quote_path(file), "mesh " + resolved, "cannot parse mesh " + resolved}) {
      if (m.rfind(theirs + again + ": ", 0) == 0) m = theirs + m.substr(theirs.size() + again.size() + 2);
    }
    return m;
  };
  try {
    SceneData scene = load_scene_text(doc.dump(), path, dir.empty() ? "." : dir, limits, set);
    for (std::string& w : scene.warnings) w = rename(w);
    return scene;
  } catch (const InputError& e) {
    throw InputError(rename(e.what()));
  }
}

}  // namespace

SceneData load_scene(const std::string& path, const LoadLimits& limits, const SceneOverrides& set) {
  namespace fs = std::filesystem;
  if (!limits.root.empty() && !inside_root(canonical_root(limits.root), path)) {
    throw InputError(one_line(path + ": the scene file resolves outside --root " + canonical_root(limits.root)));
  }
  const std::string kind = model_kind(path);
  if (!kind.empty()) return load_model_as_scene(path, kind, limits, set);
  const std::string text = read_input_file(path, limits.max_scene_bytes, "scene");
  const std::string dir = fs::path(path).parent_path().string();
  return load_scene_text(text, path, dir.empty() ? "." : dir, limits, set);
}

}  // namespace abcube
