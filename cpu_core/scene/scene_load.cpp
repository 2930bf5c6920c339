// Scene file (scene-format.md, version 1) -> SceneData. Every value is checked where it is
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

#include <cctype>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>
#include <tiny_obj_loader.h>

#include "base/error.hpp"
#include "scene/tessellate.hpp"

namespace abcube {

namespace {

using Json = nlohmann::ordered_json;  // keeps the file's order: materials are numbered as written

constexpr int MAX_IMAGE_SIDE = 32768;
constexpr int MAX_CUBE_RESOLUTION = 16384;
constexpr int MAX_BOUNCES = 64;
constexpr int MIN_SEGMENTS = 3, MAX_SEGMENTS = 4096;
constexpr size_t MAX_TRIANGLES = size_t{1} << 26;  // 67M triangles, ~5 GiB of soup
constexpr double MAX_QUAD_PLANARITY_ERROR = 1e-6;   // relative to the quad's diagonal
constexpr const char* DEFAULT_MATERIAL = "(default)";

// ---- Messages ----------------------------------------------------------------------

// One line, whatever the pieces contained.
std::string one_line(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  }
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// Shortest text that reads back as the same double.
std::string format_number(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[40];
  if (x == std::floor(x) && std::fabs(x) < 1e15) {  // integers as integers, not 2e+02
    std::snprintf(buf, sizeof buf, "%.0f", x);
    return buf;
  }
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

// A JSON value as it appears after "got" in a message, cut short when long.
std::string describe(const Json& v) {
  if (v.is_number()) return format_number(v.get<double>());
  std::string s = v.dump();
  if (s.size() > 48) s = s.substr(0, 45) + "...";
  return s;
}

std::string describe(const glm::dvec3& v) {
  return "[" + format_number(v.x) + ", " + format_number(v.y) + ", " + format_number(v.z) + "]";
}

// "parent.key", quoting keys that are not plain names (material names can be anything).
std::string member_path(const std::string& parent, const std::string& key) {
  bool plain = !key.empty();
  for (char c : key) plain = plain && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-');
  const std::string k = plain ? key : "[" + Json(key).dump() + "]";
  if (parent.empty()) return k;
  return plain ? parent + "." + k : parent + k;
}

std::string index_path(const std::string& parent, size_t i) {
  return parent + "[" + std::to_string(i) + "]";
}

// Where the messages point: the scene as named by the caller, and the folder mesh paths
// are relative to.
struct Source {
  std::string name;
  std::string base_dir;
};

[[noreturn]] void fail(const Source& src, const std::string& path, const std::string& what) {
  throw InputError(one_line(path.empty() ? src.name + ": " + what : src.name + ": " + path + ": " + what));
}

// ---- JSON text -> document ---------------------------------------------------------

// Line and column (1-based, columns in UTF-8 code points) of byte `index` of `text`.
std::string line_column(const std::string& text, size_t index) {
  index = std::min(index, text.size());
  size_t line = 1, column = 1;
  for (size_t i = 0; i < index; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      ++line;
      column = 1;
    } else if ((c & 0xC0) != 0x80) {  // not a UTF-8 continuation byte
      ++column;
    }
  }
  return std::to_string(line) + ":" + std::to_string(column);
}

// nlohmann's message without its "[json.exception...] parse error at line L, column C:"
// prefix, which we replace by our own FILE:LINE:COL.
std::string parser_message(const std::string& what) {
  std::string m = what;
  if (!m.empty() && m[0] == '[') {
    const size_t end = m.find("] ");
    if (end != std::string::npos) m = m.substr(end + 2);
  }
  if (m.rfind("parse error", 0) == 0) {
    const size_t colon = m.find(": ");
    if (colon != std::string::npos) m = m.substr(colon + 2);
  }
  if (m.rfind("number overflow", 0) == 0) m += " (numbers must be finite)";
  return m;
}

// Builds the document through the SAX interface so that a syntax error keeps its byte
// offset (numbers that overflow to infinity included) and a repeated key is caught with
// its path instead of silently replacing the first.
class DocumentBuilder final : public nlohmann::json_sax<Json> {
 public:
  Json root;
  std::string error_path, error_message;  // a repeated key
  bool syntax_error = false;
  size_t error_offset = 0;  // bytes read when the syntax error was found
  std::string error_token;  // the token that was read last

  bool null() override { return add(Json(nullptr)); }
  bool boolean(bool b) override { return add(Json(b)); }
  bool number_integer(number_integer_t v) override { return add(Json(v)); }
  bool number_unsigned(number_unsigned_t v) override { return add(Json(v)); }
  bool number_float(number_float_t v, const string_t&) override { return add(Json(v)); }
  bool string(string_t& s) override { return add(Json(std::move(s))); }
  bool binary(binary_t&) override { return add(Json(nullptr)); }  // not produced by JSON text
  bool start_object(std::size_t) override { return open(Json::object()); }
  bool start_array(std::size_t) override { return open(Json::array()); }
  bool end_object() override { return close(); }
  bool end_array() override { return close(); }

  bool key(string_t& k) override {
    Level& top = levels_.back();
    if (top.value->contains(k)) {
      error_path = member_path(path(), k);
      error_message = "field appears twice";
      return false;
    }
    top.key = k;
    return true;
  }

  bool parse_error(std::size_t position, const std::string& last_token,
                   const nlohmann::detail::exception& ex) override {
    syntax_error = true;
    error_offset = position;
    error_token = last_token;
    error_message = parser_message(ex.what());
    return false;
  }

 private:
  struct Level {
    Json* value;
    std::string key;  // the member being read, for objects
  };
  std::vector<Level> levels_;

  Json* place(Json v) {
    if (levels_.empty()) {
      root = std::move(v);
      return &root;
    }
    Level& top = levels_.back();
    if (top.value->is_array()) {
      top.value->push_back(std::move(v));
      return &top.value->back();
    }
    Json& slot = (*top.value)[top.key];
    slot = std::move(v);
    return &slot;
  }
  bool add(Json v) {
    place(std::move(v));
    return true;
  }
  bool open(Json v) {
    levels_.push_back({place(std::move(v)), {}});
    return true;
  }
  bool close() {
    levels_.pop_back();
    return true;
  }
  // Path of the innermost open container.
  std::string path() const {
    std::string p;
    for (size_t i = 1; i < levels_.size(); ++i) {
      const Level& parent = levels_[i - 1];
      p = parent.value->is_array() ? index_path(p, parent.value->size() - 1) : member_path(p, parent.key);
    }
    return p;
  }
};

Json parse_document(const std::string& text, const Source& src) {
  DocumentBuilder builder;
  const bool ok = Json::sax_parse(text, &builder, Json::input_format_t::json, true, false);
  if (builder.syntax_error) {
    // Point at the last byte read or, when that ends one literal (a string without
    // blanks, a number, a word), at the literal's start. nlohmann's "last token" can
    // span several tokens, hence the check.
    const std::string& token = builder.error_token;
    const size_t end = builder.error_offset, n = token.size();
    size_t index = end > 0 ? end - 1 : 0;
    const bool one_literal = n > 1 && token.find_first_of(" \t\r\n,:{}[]") == std::string::npos;
    if (one_literal && n <= end && end <= text.size() && text.compare(end - n, n, token) == 0) index = end - n;
    throw InputError(one_line(src.name + ":" + line_column(text, index) + ": " + builder.error_message));
  }
  if (!builder.error_path.empty()) fail(src, builder.error_path, builder.error_message);
  if (!ok) throw InputError(one_line(src.name + ":1:1: cannot parse JSON"));
  return std::move(builder.root);
}

// ---- Typed values ------------------------------------------------------------------

double read_number(const Source& src, const Json& v, const std::string& path) {
  if (!v.is_number()) fail(src, path, "must be a number, got " + describe(v));
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail(src, path, "must be finite, got " + format_number(x));
  if (std::fabs(x) > FLT_MAX) {
    fail(src, path, "out of range (magnitude must be <= 3.4e38), got " + format_number(x));
  }
  return x;
}

int read_int(const Source& src, const Json& v, const std::string& path, int lo, int hi) {
  const double x = read_number(src, v, path);
  if (x != std::floor(x)) fail(src, path, "must be an integer, got " + format_number(x));
  if (x < lo) fail(src, path, "must be >= " + std::to_string(lo) + ", got " + format_number(x));
  if (x > hi) fail(src, path, "must be <= " + std::to_string(hi) + ", got " + format_number(x));
  return static_cast<int>(x);
}

glm::dvec3 read_vec3(const Source& src, const Json& v, const std::string& path) {
  if (!v.is_array() || v.size() != 3) fail(src, path, "must be an array of 3 numbers, got " + describe(v));
  glm::dvec3 r;
  for (int i = 0; i < 3; ++i) r[i] = read_number(src, v[static_cast<size_t>(i)], index_path(path, static_cast<size_t>(i)));
  return r;
}

std::string read_string(const Source& src, const Json& v, const std::string& path) {
  if (!v.is_string()) fail(src, path, "must be a string, got " + describe(v));
  return v.get<std::string>();
}

bool read_bool(const Source& src, const Json& v, const std::string& path) {
  if (!v.is_boolean()) fail(src, path, "must be true or false, got " + describe(v));
  return v.get<bool>();
}

void check_range(const Source& src, const std::string& path, double x, double lo, double hi) {
  if (x < lo || x > hi) {
    fail(src, path, "must be in [" + format_number(lo) + ", " + format_number(hi) + "], got " + format_number(x));
  }
}

void check_non_negative(const Source& src, const std::string& path, const glm::dvec3& v) {
  for (int i = 0; i < 3; ++i) {
    if (v[i] < 0) fail(src, index_path(path, static_cast<size_t>(i)), "must be >= 0, got " + format_number(v[i]));
  }
}

// One JSON object being read. Unknown members are rejected up front, before any value
// is read (pbrt-v4 and Mitsuba 3 reject unused parameters), so a typo is reported as
// itself rather than as the missing field it was meant to be.
class Fields {
 public:
  Fields(const Source& src, const Json& j, std::string path, const std::vector<const char*>& known)
      : src_(src), j_(j), path_(std::move(path)) {
    if (!j.is_object()) fail(src, path_, "must be an object, got " + describe(j));
    for (const auto& member : j.items()) {
      bool found = false;
      for (const char* k : known) found = found || member.key() == k;
      if (found) continue;
      std::string list;
      for (const char* k : known) list += std::string(list.empty() ? "" : ", ") + k;
      fail(src, member_path(path_, member.key()), "unknown field (known here: " + list + ")");
    }
  }

  const Source& src() const { return src_; }
  const std::string& path() const { return path_; }
  std::string at(const char* key) const { return member_path(path_, key); }
  const Json* find(const char* key) const {
    const auto it = j_.find(key);
    return it == j_.end() ? nullptr : &*it;
  }
  const Json& need(const char* key) const {
    const Json* v = find(key);
    if (!v) fail(src_, at(key), "missing required field");
    return *v;
  }

  double number(const char* key) const { return read_number(src_, need(key), at(key)); }
  double number(const char* key, double fallback) const {
    const Json* v = find(key);
    return v ? read_number(src_, *v, at(key)) : fallback;
  }
  glm::dvec3 vec3(const char* key) const { return read_vec3(src_, need(key), at(key)); }
  glm::dvec3 vec3(const char* key, const glm::dvec3& fallback) const {
    const Json* v = find(key);
    return v ? read_vec3(src_, *v, at(key)) : fallback;
  }
  int integer(const char* key, int fallback, int lo, int hi) const {
    const Json* v = find(key);
    return v ? read_int(src_, *v, at(key), lo, hi) : fallback;
  }
  // A number in [lo, hi], or the fallback when absent.
  double number_in(const char* key, double fallback, double lo, double hi) const {
    const double x = number(key, fallback);
    check_range(src_, at(key), x, lo, hi);
    return x;
  }

 private:
  const Source& src_;
  const Json& j_;
  std::string path_;
};

// ---- Sections ----------------------------------------------------------------------

Camera read_camera(const Fields& f) {
  Camera c;
  c.position = f.vec3("position");
  c.look_at = f.vec3("look_at");
  c.up = f.vec3("up", c.up);
  c.fov_y_deg = f.number("fov_y", c.fov_y_deg);
  c.width = f.integer("width", c.width, 1, MAX_IMAGE_SIDE);
  c.height = f.integer("height", c.height, 1, MAX_IMAGE_SIDE);
  const Source& src = f.src();
  if (!(c.fov_y_deg > 0 && c.fov_y_deg < 180)) {
    fail(src, f.at("fov_y"), "must be > 0 and < 180 (degrees), got " + format_number(c.fov_y_deg));
  }
  const glm::dvec3 view = c.look_at - c.position;
  const double scale = std::max(glm::length(c.position), glm::length(c.look_at));
  if (!(glm::length(view) > 1e-12 * scale)) {
    fail(src, f.at("look_at"), "must differ from camera.position, got " + describe(c.look_at));
  }
  const double up_length = glm::length(c.up);
  if (!(up_length > 0)) fail(src, f.at("up"), "must be nonzero, got " + describe(c.up));
  // sin of the angle between up and the view direction
  if (!(glm::length(glm::cross(glm::normalize(view), c.up / up_length)) > 1e-6)) {
    fail(src, f.at("up"), "must not be parallel to the view direction (look_at - position), got " +
                              describe(c.up));
  }
  return c;
}

PointLight read_light(const Fields& f) {
  const std::string type = read_string(f.src(), f.need("type"), f.at("type"));
  if (type != "point") fail(f.src(), f.at("type"), "must be \"point\", got " + describe(Json(type)));
  PointLight l;
  l.position = f.vec3("position");
  l.color = f.vec3("color", l.color);
  check_non_negative(f.src(), f.at("color"), l.color);
  if (const Json* v = f.find("cast_shadows")) l.cast_shadows = read_bool(f.src(), *v, f.at("cast_shadows"));
  return l;
}

// Phong material with the format's defaults (scene-format.md "materials").
Material read_material(const Fields& f, const std::string& name) {
  Material m;
  m.name = name;
  m.color = f.vec3("color", m.color);
  check_non_negative(f.src(), f.at("color"), m.color);
  m.ambient = f.number_in("ambient", m.ambient, 0, 1);
  m.diffuse = f.number_in("diffuse", m.diffuse, 0, 1);
  m.specular = f.number_in("specular", m.specular, 0, 1);
  m.shininess = f.number("shininess", m.shininess);
  if (m.shininess < 0) fail(f.src(), f.at("shininess"), "must be >= 0, got " + format_number(m.shininess));
  m.reflect = f.number_in("reflect", m.reflect, 0, 1);
  m.transmit = f.number_in("transmit", m.transmit, 0, 1);
  m.ior = f.number("ior", m.ior);
  if (m.ior < 1) fail(f.src(), f.at("ior"), "must be >= 1, got " + format_number(m.ior));
  m.opacity = f.number_in("opacity", m.opacity, 0, 1);
  return m;
}

RenderSettings read_render(const Fields& f) {
  RenderSettings r;
  if (const Json* v = f.find("method")) {
    const std::string name = read_string(f.src(), *v, f.at("method"));
    if (!parse_method(name, &r.method)) {
      fail(f.src(), f.at("method"),
           "must be one of abuffer, zbuffer, envmap, raytrace, gpu, got " + describe(*v));
    }
  }
  r.cube_resolution = f.integer("cube_resolution", r.cube_resolution, 1, MAX_CUBE_RESOLUTION);
  r.max_depth = f.integer("max_depth", r.max_depth, 0, MAX_BOUNCES);
  if (const Json* v = f.find("fresnel")) r.fresnel = read_bool(f.src(), *v, f.at("fresnel"));
  if (const Json* v = f.find("error_target")) {
    r.error_target = read_number(f.src(), *v, f.at("error_target"));
    check_range(f.src(), f.at("error_target"), r.error_target, 1e-12, 0.5);
  }
  return r;
}

// ---- Objects -----------------------------------------------------------------------

// What loading the objects shares: the scene being filled, material names, and the
// materials already made from MTL files (keyed by resolved OBJ path and MTL name).
struct LoadState {
  const Source& src;
  SceneData& scene;
  std::map<std::string, uint32_t> material_by_name;
  std::map<std::string, uint32_t> mtl_materials;
  int default_material = -1;
};

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

Transform read_transform(const Fields& f) {
  Transform t;
  t.translate = f.vec3("translate", t.translate);
  t.rotate_deg = f.vec3("rotate_deg", t.rotate_deg);
  if (const Json* s = f.find("scale")) {
    t.scale = s->is_number() ? glm::dvec3(read_number(f.src(), *s, f.at("scale")))
                             : read_vec3(f.src(), *s, f.at("scale"));
    for (int i = 0; i < 3; ++i) {
      if (t.scale[i] == 0) {
        fail(f.src(), s->is_number() ? f.at("scale") : index_path(f.at("scale"), static_cast<size_t>(i)),
             "must be nonzero, got 0");
      }
    }
  }
  return t;
}

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

LocalMesh read_sphere(const Fields& f, size_t triangles_so_far) {
  const glm::dvec3 center = f.vec3("center");
  const double radius = f.number("radius");
  if (!(radius > 0)) fail(f.src(), f.at("radius"), "must be > 0, got " + format_number(radius));
  const int segments = f.integer("segments", 32, MIN_SEGMENTS, MAX_SEGMENTS);
  if (triangles_so_far + sphere_triangle_count(segments) > MAX_TRIANGLES) {
    fail(f.src(), f.at("segments"), "the scene would exceed " + std::to_string(MAX_TRIANGLES) +
                                        " triangles, got " + std::to_string(segments));
  }
  return tessellate_sphere(center, radius, segments);
}

// The format's material from an MTL entry: Kd -> color, mean of Ks -> specular,
// Ns -> shininess, d -> opacity, Ni -> ior (Ni below 1, which exporters write for
// "unset", is taken as 1). `where` prefixes messages.
Material convert_mtl(const LoadState& st, const std::string& path, const std::string& where,
                     const tinyobj::material_t& in, const std::string& name) {
  Material m;
  m.name = name;
  m.color = glm::dvec3(in.diffuse[0], in.diffuse[1], in.diffuse[2]);
  m.specular = (static_cast<double>(in.specular[0]) + in.specular[1] + in.specular[2]) / 3.0;
  m.shininess = in.shininess;
  m.opacity = in.dissolve;
  m.ior = std::max(1.0, static_cast<double>(in.ior));
  auto bad = [&](const char* what, double x) {
    fail(st.src, path, where + ": material \"" + in.name + "\": " + what + ", got " + format_number(x));
  };
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(m.color[i]) || m.color[i] < 0) bad("Kd must be finite and >= 0", m.color[i]);
  }
  if (!(m.specular >= 0 && m.specular <= 1)) bad("mean Ks must be in [0, 1]", m.specular);
  if (!(m.shininess >= 0 && std::isfinite(m.shininess))) bad("Ns must be finite and >= 0", m.shininess);
  if (!(m.opacity >= 0 && m.opacity <= 1)) bad("d must be in [0, 1]", m.opacity);
  if (!std::isfinite(m.ior)) bad("Ni must be finite", m.ior);
  return m;
}

// Scene material index for each MTL material of an OBJ, made once per file.
std::vector<uint32_t> mtl_material_ids(LoadState& st, const std::string& path, const std::string& file,
                                       const std::string& resolved, const tinyobj::ObjReader& obj) {
  std::vector<uint32_t> ids;
  for (const tinyobj::material_t& mtl : obj.GetMaterials()) {
    const std::string key = resolved + '\n' + mtl.name;
    auto it = st.mtl_materials.find(key);
    if (it == st.mtl_materials.end()) {
      const uint32_t id = add_material(st, convert_mtl(st, path, resolved, mtl, file + ":" + mtl.name));
      it = st.mtl_materials.emplace(key, id).first;
    }
    ids.push_back(it->second);
  }
  return ids;
}

// First line of a tinyobjloader message that contains `needle`, or "".
std::string find_line(const std::string& text, const char* needle) {
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.find(needle) != std::string::npos) return line;
  }
  return "";
}

// Appends one OBJ face (already validated) to `out`, triangulating polygons.
void add_obj_face(const tinyobj::attrib_t& a, const tinyobj::index_t* corners, size_t n, int material,
                  LocalMesh* out) {
  std::vector<glm::dvec3> p(n), nrm(n, glm::dvec3(0.0));
  bool smooth = true;
  for (size_t k = 0; k < n; ++k) {
    const size_t v = static_cast<size_t>(corners[k].vertex_index);
    p[k] = glm::dvec3(a.vertices[3 * v], a.vertices[3 * v + 1], a.vertices[3 * v + 2]);
    const int ni = corners[k].normal_index;
    smooth = smooth && ni >= 0;
    if (ni >= 0) {
      const size_t w = static_cast<size_t>(ni);
      nrm[k] = glm::dvec3(a.normals[3 * w], a.normals[3 * w + 1], a.normals[3 * w + 2]);
    }
  }
  if (!smooth) std::fill(nrm.begin(), nrm.end(), glm::dvec3(0.0));  // zero: flat
  for (const auto& t : triangulate_polygon(p)) {
    for (int k : t) {
      out->positions.push_back(p[static_cast<size_t>(k)]);
      out->normals.push_back(nrm[static_cast<size_t>(k)]);
    }
    out->material.push_back(material);
  }
}

std::string resolve_mesh_path(const Source& src, const std::string& file) {
  namespace fs = std::filesystem;
  const fs::path p(file);
  return (p.is_absolute() ? p : fs::path(src.base_dir) / p).lexically_normal().string();
}

// A mesh object's triangles from a Wavefront OBJ. With `use_mtl`, its MTL materials
// become scene materials named "FILE:NAME", and faces without one get the default.
LocalMesh read_obj(LoadState& st, const Fields& f, bool use_mtl) {
  const std::string path = f.at("file");
  const std::string file = read_string(st.src, f.need("file"), path);
  if (file.empty()) fail(st.src, path, "must name an OBJ file, got \"\"");
  const std::string resolved = resolve_mesh_path(st.src, file);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(resolved, ec)) {
    const bool exists = std::filesystem::exists(resolved, ec);
    fail(st.src, path, "cannot read mesh \"" + resolved + "\": " + (exists ? "not a regular file" : "no such file"));
  }
  tinyobj::ObjReaderConfig config;
  config.triangulate = false;  // polygons are ear-clipped here, keeping their winding
  config.vertex_color = false;
  tinyobj::ObjReader obj;
  if (!obj.ParseFromFile(resolved, config)) {
    fail(st.src, path, "cannot parse mesh \"" + resolved + "\": " + obj.Error());
  }
  if (use_mtl) {
    const std::string missing = find_line(obj.Warning(), "not found");
    if (!missing.empty()) fail(st.src, path, "mesh \"" + resolved + "\": " + missing);
  }
  const std::vector<uint32_t> mtl_ids = use_mtl ? mtl_material_ids(st, path, file, resolved, obj) : std::vector<uint32_t>{};
  const tinyobj::attrib_t& a = obj.GetAttrib();
  const int vertex_count = static_cast<int>(a.vertices.size() / 3);
  const int normal_count = static_cast<int>(a.normals.size() / 3);
  LocalMesh m;
  for (const tinyobj::shape_t& shape : obj.GetShapes()) {
    size_t offset = 0;
    for (size_t face = 0; face < shape.mesh.num_face_vertices.size(); ++face) {
      const size_t n = shape.mesh.num_face_vertices[face];
      const tinyobj::index_t* corners = &shape.mesh.indices[offset];
      offset += n;
      for (size_t k = 0; k < n; ++k) {
        if (corners[k].vertex_index < 0 || corners[k].vertex_index >= vertex_count ||
            corners[k].normal_index >= normal_count) {
          fail(st.src, path, "mesh \"" + resolved + "\": face of shape \"" + shape.name + "\" has an index out of range");
        }
      }
      const int mtl = face < shape.mesh.material_ids.size() ? shape.mesh.material_ids[face] : -1;
      int material = -1;  // the object's own
      if (use_mtl) {
        material = mtl >= 0 && static_cast<size_t>(mtl) < mtl_ids.size() ? static_cast<int>(mtl_ids[static_cast<size_t>(mtl)])
                                                                         : static_cast<int>(default_material(st));
      }
      add_obj_face(a, corners, n, material, &m);
      if (st.scene.triangles->triangle_count() + m.triangle_count() > MAX_TRIANGLES) {
        fail(st.src, path, "the scene would exceed " + std::to_string(MAX_TRIANGLES) + " triangles");
      }
    }
  }
  return m;
}

// Triangles of one object in object space, by type.
LocalMesh read_geometry(LoadState& st, const Fields& f, const std::string& type, bool has_material) {
  if (type == "triangle") {
    const std::vector<glm::dvec3> p = read_points(f, "vertices", 3);
    return tessellate_triangle(p[0], p[1], p[2]);
  }
  if (type == "quad") return read_quad(f);
  if (type == "box") return read_box(f);
  if (type == "sphere") return read_sphere(f, st.scene.triangles->triangle_count());
  return read_obj(st, f, !has_material);
}

void read_object(LoadState& st, const Json& v, size_t index) {
  const std::string path = index_path("objects", index);
  if (!v.is_object()) fail(st.src, path, "must be an object, got " + describe(v));
  const auto type_it = v.find("type");
  if (type_it == v.end()) fail(st.src, member_path(path, "type"), "missing required field");
  const std::string type = read_string(st.src, *type_it, member_path(path, "type"));
  std::vector<const char*> known;
  if (type == "triangle" || type == "quad") {
    known = {"type", "vertices", "material", "transform"};
  } else if (type == "box") {
    known = {"type", "min", "max", "material", "transform"};
  } else if (type == "sphere") {
    known = {"type", "center", "radius", "segments", "material", "transform"};
  } else if (type == "mesh") {
    known = {"type", "file", "material", "transform"};
  } else {
    fail(st.src, member_path(path, "type"), "must be one of triangle, quad, box, sphere, mesh, got " + describe(*type_it));
  }
  const Fields f(st.src, v, path, known);

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
  const LocalMesh local = read_geometry(st, f, type, material != nullptr);
  // Without a "material", a primitive gets the default and a mesh its per-face MTL ones.
  if (!material && local.material.empty()) obj.material = default_material(st);
  if (st.scene.triangles->triangle_count() + local.triangle_count() > MAX_TRIANGLES) {
    fail(st.src, path, "the scene would exceed " + std::to_string(MAX_TRIANGLES) + " triangles");
  }

  TriangleSoup& soup = st.scene.triangles.edit();
  const uint32_t id = static_cast<uint32_t>(st.scene.objects.size());
  obj.first_triangle = static_cast<uint32_t>(soup.triangle_count());
  st.scene.dropped_triangles += append_triangles(local, make_affine_map(transform), id, obj.material, &soup);
  obj.triangle_count = static_cast<uint32_t>(soup.triangle_count() - obj.first_triangle);
  if (!material && !local.material.empty()) {
    obj.material = obj.triangle_count > 0 ? soup.material_id[obj.first_triangle] : default_material(st);
  }
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
    const Fields f(st.src, entry.value(), path,
                   {"color", "ambient", "diffuse", "specular", "shininess", "reflect", "transmit", "ior", "opacity"});
    st.material_by_name[entry.key()] = add_material(st, read_material(f, entry.key()));
  }
}

const Json& read_array(const Source& src, const Json& v, const std::string& path) {
  if (!v.is_array()) fail(src, path, "must be an array, got " + describe(v));
  return v;
}

SceneData read_scene(const Json& doc, const Source& src) {
  const Fields top(src, doc, "",
                   {"version", "camera", "background", "ambient", "lights", "materials", "objects", "render"});
  const Json& version = top.need("version");
  if (!version.is_number() || version.get<double>() != 1.0) {
    fail(src, "version", "must be 1 (the only version this program reads), got " + describe(version));
  }
  SceneData scene;
  scene.file = src.name;
  scene.camera = read_camera(Fields(src, top.need("camera"), "camera",
                                    {"position", "look_at", "up", "fov_y", "width", "height"}));
  scene.background = top.vec3("background", scene.background);
  check_non_negative(src, "background", scene.background);
  scene.ambient = top.vec3("ambient", scene.ambient);
  check_non_negative(src, "ambient", scene.ambient);
  if (const Json* lights = top.find("lights")) {
    const Json& list = read_array(src, *lights, "lights");
    for (size_t i = 0; i < list.size(); ++i) {
      scene.lights.push_back(read_light(Fields(src, list[i], index_path("lights", i),
                                               {"type", "position", "color", "cast_shadows"})));
    }
  }
  LoadState st{src, scene, {}, {}, -1};
  if (const Json* materials = top.find("materials")) read_materials(st, *materials);
  const Json& objects = read_array(src, top.need("objects"), "objects");
  for (size_t i = 0; i < objects.size(); ++i) read_object(st, objects[i], i);
  if (const Json* render = top.find("render")) {
    scene.render = read_render(Fields(src, *render, "render", {"method", "cube_resolution", "max_depth", "fresnel", "error_target"}));
  }
  return scene;
}

// Bytes per unit of work, for the estimate: a camera pixel holds its colour and A-buffer
// fragment headroom; a cube texel its distance and fragment headroom; a triangle its
// soup entry (3 positions, 3 normals, 2 ids), acceleration-structure headroom (64), and
// the searches' per-triangle data (search.hpp SearchContext: plane 32, refinement bounds
// 128, neighbours 12 bytes, and 120 more while the neighbours are being built).
constexpr uint64_t PIXEL_BYTES = 3 * sizeof(float) + 64;
constexpr uint64_t TEXEL_BYTES = 64;
constexpr uint64_t TRIANGLE_BYTES = 6 * sizeof(glm::vec3) + 2 * sizeof(uint32_t) + 64 + 32 + 128 + 12 + 120;

}  // namespace

SceneData load_scene_text(const std::string& text, const std::string& name, const std::string& base_dir) {
  const Source src{name, base_dir.empty() ? "." : base_dir};
  return read_scene(parse_document(text, src), src);
}

SceneData load_scene(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(one_line(path + ": cannot read scene: is a directory"));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(one_line(path + ": cannot read scene: " + std::strerror(errno)));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(one_line(path + ": cannot read scene: read error"));
  const std::string dir = fs::path(path).parent_path().string();
  return load_scene_text(text.str(), path, dir.empty() ? "." : dir);
}

uint64_t estimate_render_bytes(const SceneData& scene) {
  const uint64_t pixels = static_cast<uint64_t>(scene.camera.width) * static_cast<uint64_t>(scene.camera.height);
  const uint64_t n = static_cast<uint64_t>(scene.render.cube_resolution);
  return pixels * PIXEL_BYTES + 6 * n * n * TEXEL_BYTES + scene.triangles->triangle_count() * TRIANGLE_BYTES;
}

void check_render_size(const SceneData& scene, uint64_t budget_bytes) {
  const uint64_t need = estimate_render_bytes(scene);
  if (need <= budget_bytes) return;
  constexpr uint64_t MIB = uint64_t{1} << 20;
  throw InputError(one_line(scene.file + ": render: estimated " + std::to_string((need + MIB - 1) / MIB) +
                            " MiB for " + std::to_string(scene.camera.width) + "x" +
                            std::to_string(scene.camera.height) + " and cube " +
                            std::to_string(scene.render.cube_resolution) + " exceeds available memory " +
                            std::to_string(budget_bytes / MIB) + " MiB"));
}

}  // namespace abcube
