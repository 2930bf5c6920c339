// The glTF file's JSON checked before tinygltf reads it (scene_gltf_reader.hpp): the version,
// the required extensions, the members' types and the files it names.
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

#include "base/error.hpp"
#include "base/input_file.hpp"
#include "scene/scene_gltf_reader.hpp"

namespace abcube::detail::gltf {

namespace {

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
       {{"bufferView", Kind::uint},
        {"byteOffset", Kind::uint},
        {"componentType", Kind::uint},
        {"normalized", Kind::boolean},
        {"count", Kind::uint},
        {"type", Kind::string},
        {"max", Kind::number_array},
        {"min", Kind::number_array},
        {"sparse", Kind::object}}},
      {"animations", {}},
      {"buffers", {{"uri", Kind::string}, {"byteLength", Kind::uint}}},
      {"bufferViews",
       {{"buffer", Kind::uint},
        {"byteOffset", Kind::uint},
        {"byteLength", Kind::uint},
        {"byteStride", Kind::uint},
        {"target", Kind::uint}}},
      {"cameras", {{"type", Kind::string}, {"perspective", Kind::object}, {"orthographic", Kind::object}}},
      {"images", {{"uri", Kind::string}, {"mimeType", Kind::string}, {"bufferView", Kind::uint}}},
      {"materials",
       {{"pbrMetallicRoughness", Kind::object},
        {"emissiveFactor", Kind::number_array},
        {"alphaMode", Kind::string},
        {"alphaCutoff", Kind::number},
        {"doubleSided", Kind::boolean}}},
      {"meshes", {{"primitives", Kind::object_array}, {"weights", Kind::number_array}}},
      {"nodes",
       {{"camera", Kind::uint},
        {"children", Kind::uint_array},
        {"skin", Kind::uint},
        {"matrix", Kind::number_array},
        {"mesh", Kind::uint},
        {"rotation", Kind::number_array},
        {"scale", Kind::number_array},
        {"translation", Kind::number_array},
        {"weights", Kind::number_array}}},
      {"samplers", {}},
      {"scenes", {{"nodes", Kind::uint_array}}},
      {"skins", {}},
      {"textures", {{"sampler", Kind::uint}, {"source", Kind::uint}}},
  };
  return schema;
}

const std::vector<Member> PRIMITIVE = {{"attributes", Kind::object},    {"indices", Kind::uint},
                                       {"material", Kind::uint},        {"mode", Kind::uint},
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
    check_members(
        bad, *it, tat,
        {{"index", Kind::uint}, {"texCoord", Kind::uint}, {"scale", Kind::number}, {"strength", Kind::number}});
    if (!it->contains("index")) bad(member_path(tat, "index"), "missing required field");
  };
  check_members(
      bad, m, at,
      {{"normalTexture", Kind::object}, {"occlusionTexture", Kind::object}, {"emissiveTexture", Kind::object}});
  for (const char* key : {"normalTexture", "occlusionTexture", "emissiveTexture"}) texture_info(m, key);
  const auto pbr = m.find("pbrMetallicRoughness");
  if (pbr == m.end()) return;
  const std::string pat = member_path(at, "pbrMetallicRoughness");
  check_members(bad, *pbr, pat,
                {{"baseColorFactor", Kind::number_array},
                 {"baseColorTexture", Kind::object},
                 {"metallicFactor", Kind::number},
                 {"roughnessFactor", Kind::number},
                 {"metallicRoughnessTexture", Kind::object}});
  for (const char* key : {"baseColorTexture", "metallicRoughnessTexture"}) {
    const auto it = pbr->find(key);
    if (it == pbr->end()) continue;
    check_members(bad, *it, member_path(pat, key), {{"index", Kind::uint}, {"texCoord", Kind::uint}});
    if (!it->contains("index")) bad(member_path(member_path(pat, key), "index"), "missing required field");
  }
}

// An image stored in a buffer view (glTF 5.11, 5.17): the view must exist and lie wholly
// inside its buffer's declared byteLength. tinygltf sizes every buffer's data to that
// byteLength but hands an image's view to the image callback unchecked, so a view past its
// buffer would be read past the end of the buffer's data. (The views of accessors are
// checked against the data itself when the geometry is read.)
void check_image_views(const std::function<void(const std::string&, const std::string&)>& bad, const Json& doc) {
  const auto images = doc.find("images");
  if (images == doc.end()) return;
  const auto views = doc.find("bufferViews");
  const auto buffers = doc.find("buffers");
  const size_t view_count = views == doc.end() ? 0 : views->size();
  const size_t buffer_count = buffers == doc.end() ? 0 : buffers->size();
  for (size_t i = 0; i < images->size(); ++i) {
    const auto it = (*images)[i].find("bufferView");
    if (it == (*images)[i].end()) continue;
    const std::string at = member_path(index_path("images", i), "bufferView");
    const uint64_t index = it->get<uint64_t>();
    if (index >= view_count) {
      bad(at, std::to_string(index) + " names no buffer view (the file has " + std::to_string(view_count) + ")");
    }
    const Json& view = (*views)[index];
    const std::string view_at = index_path("bufferViews", index);
    const uint64_t buffer = view.value("buffer", uint64_t{0});
    if (!view.contains("buffer") || buffer >= buffer_count) {
      bad(at, view_at + " names no buffer (the file has " + std::to_string(buffer_count) + ")");
    }
    const uint64_t offset = view.value("byteOffset", uint64_t{0});
    const uint64_t length = view.value("byteLength", uint64_t{0});
    const uint64_t capacity = (*buffers)[buffer].value("byteLength", uint64_t{0});
    if (offset > capacity || length > capacity - offset) {
      bad(at, view_at + " (byteOffset " + std::to_string(offset) + " + byteLength " + std::to_string(length) +
                  ") passes the end of buffers[" + std::to_string(buffer) + "] (byteLength " +
                  std::to_string(capacity) + ")");
    }
  }
}

}  // namespace

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

GlbChunks read_glb(const std::string& bytes) {
  const auto u32 = [&](size_t at) {
    uint32_t v = 0;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  GlbChunks out;
  const auto refuse = [&](const std::string& why) {
    out.problem = "not a valid binary glTF: " + why;
    return out;
  };
  if (bytes.size() < 12) return refuse("shorter than its 12-byte header");
  if (u32(4) != 2) {
    out.problem = "binary glTF version " + std::to_string(u32(4)) + ": only glTF 2.0 is read";
    return out;
  }
  // The header's length bounds every chunk; bytes after it are not part of the container.
  const uint64_t length = u32(8);
  if (length > bytes.size()) {
    return refuse("the header says " + std::to_string(length) + " bytes, the file has " + std::to_string(bytes.size()));
  }
  // Chunks: an 8-byte header (length, type), then the data, each wholly inside `length`.
  // The first is JSON; a BIN chunk may follow it.
  uint64_t at = 12;
  for (int index = 0; at < length; ++index) {
    if (at + 8 > length) return refuse("chunk " + std::to_string(index) + " has no room for its 8-byte header");
    const uint64_t size = u32(static_cast<size_t>(at));
    const uint32_t type = u32(static_cast<size_t>(at) + 4);
    if (at + 8 + size > length) {
      return refuse("chunk " + std::to_string(index) + " claims " + std::to_string(size) + " bytes, " +
                    std::to_string(length - at - 8) + " remain");
    }
    if (index == 0 && type != 0x4E4F534Au /* JSON */) return refuse("the first chunk is not JSON");
    if (index == 0) out.json = bytes.substr(static_cast<size_t>(at) + 8, static_cast<size_t>(size));
    at += 8 + size;
  }
  if (at == 12) return refuse("no JSON chunk");
  return out;
}

void check_document(const Json& doc, const BadAt& bad, const CheckFile& check_file) {
  if (!doc.is_object()) bad("", "must hold a JSON object, got " + describe(doc));
  check_extensions(bad, doc, "");
  const auto asset = doc.find("asset");
  if (asset == doc.end() || !asset->is_object()) bad("asset", "missing (a glTF 2.0 file has asset.version \"2.0\")");
  const auto version = asset->find("version");
  if (version == asset->end() || !version->is_string() || version->get<std::string>().rfind("2.", 0) != 0) {
    bad("asset.version",
        "only glTF 2.0 is read, got " + (version == asset->end() ? std::string("nothing") : describe(*version)));
  }
  check_members(bad, doc, "",
                {{"scene", Kind::uint},
                 {"extensionsUsed", Kind::string_array},
                 {"extensionsRequired", Kind::string_array},
                 {"extensions", Kind::object}});
  if (const auto req = doc.find("extensionsRequired"); req != doc.end()) {
    for (size_t i = 0; i < req->size(); ++i) {
      const std::string name = (*req)[i].get<std::string>();
      if (!SUPPORTED_REQUIRED.count(name)) {
        bad(index_path("extensionsRequired", i),
            quote(name) +
                " is not supported (supported: KHR_lights_punctual, KHR_materials_transmission, "
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
      check_members(bad, element, at, members);
      check_members(bad, element, at, {{"name", Kind::string}, {"extensions", Kind::object}});
      if (array == "meshes") {
        const auto prims = element.find("primitives");
        if (prims == element.end()) bad(at, "primitives: missing required field");
        for (size_t k = 0; k < prims->size(); ++k) {
          const std::string pat = index_path(member_path(at, "primitives"), k);
          check_members(bad, (*prims)[k], pat, PRIMITIVE);
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
      if (array == "materials") check_material(bad, element, at);
    }
  }
  check_image_views(bad, doc);
}

}  // namespace abcube::detail::gltf
