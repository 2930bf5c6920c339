// glTF accessors and primitives into triangles (scene_gltf_reader.hpp).
#include <algorithm>
#include <atomic>
#include <cstdint>
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
#include "base/parallel.hpp"
#include "scene/scene_gltf_reader.hpp"

namespace abcube::detail::gltf {

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

// Items of an accessor or a primitive handed to a thread at a time.
constexpr size_t ACCESSOR_RUN = size_t{1} << 15;

const char* mode_name(int mode) {
  static const char* names[] = {"POINTS",    "LINES",          "LINE_LOOP",   "LINE_STRIP",
                                "TRIANGLES", "TRIANGLE_STRIP", "TRIANGLE_FAN"};
  return mode >= 0 && mode <= 6 ? names[mode] : "unknown";
}

glm::dmat4 GltfReader::local_matrix(const tg::Node& n, const std::string& at) const {
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

void GltfReader::visit(int index, const glm::dmat4& parent, const std::string& from, std::vector<bool>* on_path) {
  if (index < 0 || static_cast<size_t>(index) >= model_.nodes.size()) {
    bad(from, "node " + std::to_string(index) + " out of range (" + std::to_string(model_.nodes.size()) + " nodes)");
  }
  const std::string at = index_path("nodes", static_cast<size_t>(index));
  if ((*on_path)[static_cast<size_t>(index)]) bad(at, "is its own ancestor (the node hierarchy has a cycle)");
  if (++visits_ > MAX_NODE_VISITS)
    bad(at, "the node hierarchy instances more than " + std::to_string(MAX_NODE_VISITS) + " nodes");
  (*on_path)[static_cast<size_t>(index)] = true;
  const tg::Node& n = model_.nodes[static_cast<size_t>(index)];
  const glm::dmat4 world = parent * local_matrix(n, at);
  if (n.skin >= 0) note("skins (meshes drawn unskinned)");
  if (n.mesh >= 0) {
    if (static_cast<size_t>(n.mesh) >= model_.meshes.size()) {
      bad(member_path(at, "mesh"),
          "index " + std::to_string(n.mesh) + " out of range (" + std::to_string(model_.meshes.size()) + " meshes)");
    }
    const tg::Mesh& mesh = model_.meshes[static_cast<size_t>(n.mesh)];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      add_primitive(mesh.primitives[p],
                    index_path(index_path("meshes", static_cast<size_t>(n.mesh)) + ".primitives", p), world);
    }
  }
  if (n.camera >= 0) add_camera(n.camera, at, world);
  const auto light = n.extensions.find("KHR_lights_punctual");
  if (light != n.extensions.end() && light->second.Has("light")) add_light(light->second.Get("light"), at, world);
  for (int c : n.children) visit(c, world, member_path(at, "children"), on_path);
  (*on_path)[static_cast<size_t>(index)] = false;
}

// Where `count` elements of `element` bytes start in bufferView `view` at `offset`, and their
// stride; refused (at `vat`) unless they lie inside the view and the view inside its buffer.
const unsigned char* GltfReader::view_bytes(int view, size_t offset, size_t count, size_t element, size_t* stride,
                                            const std::string& vat) const {
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
}

// The accessor's sparse substitution (glTF 3.6.2.3) applied to its values.
void GltfReader::apply_sparse(const tg::Accessor& a, const std::string& aat, size_t elem, Accessed* accessed) const {
  Accessed& out = *accessed;
  const size_t n = a.sparse.count < 0 ? 0 : static_cast<size_t>(a.sparse.count);
  const int ict = a.sparse.indices.componentType;
  if (ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
    bad(aat + ".sparse.indices",
        std::string("componentType ") + component_name(ict) + ", expected an unsigned integer");
  }
  size_t istride = 0, vstride = 0;
  const unsigned char* ip =
      view_bytes(a.sparse.indices.bufferView, static_cast<size_t>(std::max(0, a.sparse.indices.byteOffset)), n,
                 component_bytes(ict), &istride, aat + ".sparse.indices");
  const unsigned char* vp =
      view_bytes(a.sparse.values.bufferView, static_cast<size_t>(std::max(0, a.sparse.values.byteOffset)), n, elem,
                 &vstride, aat + ".sparse.values");
  istride = component_bytes(ict);  // sparse data is tightly packed
  vstride = elem;
  for (size_t i = 0; i < n; ++i) {
    const double target = read_component(ip + i * istride, ict, false);
    if (target >= static_cast<double>(a.count)) {
      bad(aat + ".sparse.indices",
          "index " + format_number(target) + " out of range (" + std::to_string(a.count) + " elements)");
    }
    for (int k = 0; k < out.n; ++k) {
      out.values[static_cast<size_t>(target) * static_cast<size_t>(out.n) + static_cast<size_t>(k)] = read_component(
          vp + i * vstride + static_cast<size_t>(k) * component_bytes(a.componentType), a.componentType, a.normalized);
    }
  }
}

// The accessor's elements as doubles (normalized integers mapped), checked against the
// types allowed and against its buffer view and buffer.
Accessed GltfReader::read_accessor(int index, const std::string& at, std::initializer_list<int> types,
                                   std::initializer_list<int> component_types, bool allow_normalized_only) const {
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
  if (a.bufferView >= 0) {
    size_t stride = 0;
    const unsigned char* p = view_bytes(a.bufferView, a.byteOffset, a.count, elem, &stride, aat);
    const size_t cb = component_bytes(a.componentType);
    parallel_for_runs(a.count, ACCESSOR_RUN, st_.limits.threads, [&](size_t i) {
      for (int k = 0; k < out.n; ++k) {
        out.values[i * static_cast<size_t>(out.n) + static_cast<size_t>(k)] =
            read_component(p + i * stride + static_cast<size_t>(k) * cb, a.componentType, a.normalized);
      }
    });
  }
  if (a.sparse.isSparse) apply_sparse(a, aat, elem, &out);
  std::atomic<size_t> first_bad{SIZE_MAX};  // the first value that is not finite
  parallel_for_runs(out.values.size(), ACCESSOR_RUN, st_.limits.threads, [&](size_t i) {
    if (std::isfinite(out.values[i])) return;
    size_t seen = first_bad.load();
    while (i < seen && !first_bad.compare_exchange_weak(seen, i)) {
    }
  });
  if (const size_t i = first_bad.load(); i != SIZE_MAX) {
    bad(aat, "element " + std::to_string(i / static_cast<size_t>(out.n)) + " is not finite (" +
                 format_number(out.values[i]) + ")");
  }
  return out;
}

void GltfReader::add_primitive(const tg::Primitive& prim, const std::string& at, const glm::dmat4& world) {
  const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  if (mode > TINYGLTF_MODE_TRIANGLE_FAN) bad(member_path(at, "mode"), "must be 0 ... 6, got " + std::to_string(mode));
  if (mode < TINYGLTF_MODE_TRIANGLES) {
    note("points and lines (" + std::string(mode_name(mode)) + " primitives skipped)");
    return;
  }
  if (!prim.targets.empty()) note("morph targets (the base shape is drawn)");
  if (prim.extensions.count("KHR_draco_mesh_compression"))
    note("KHR_draco_mesh_compression (its uncompressed fallback is drawn)");
  const auto pos = prim.attributes.find("POSITION");
  if (pos == prim.attributes.end()) {
    note("primitives without POSITION");
    return;
  }
  const std::string aat = member_path(at, "attributes");
  const Accessed p =
      read_accessor(pos->second, member_path(aat, "POSITION"), {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT});
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
        bad(member_path(aat, key.c_str()),
            std::to_string(uv.count) + " elements, POSITION has " + std::to_string(p.count));
      }
    }
  }
  const std::vector<std::array<uint32_t, 3>> tris = primitive_triangles(prim, at, mode, p.count);
  check_triangle_cap(st_, path_, out_.triangle_count() + tris.size());
  if (st_.scene.triangles->triangle_count() + out_.triangle_count() + tris.size() > MAX_TRIANGLES) {
    bad("", "the scene would exceed " + std::to_string(MAX_TRIANGLES) + " triangles");
  }
  append_triangles(tris, p, nrm, uv, material, world);
}

std::vector<std::array<uint32_t, 3>> GltfReader::primitive_triangles(const tg::Primitive& prim, const std::string& at,
                                                                     int mode, size_t count) {
  // The vertex list: the indices, or 0 ... count - 1.
  std::vector<uint32_t> list;
  if (prim.indices >= 0) {
    const std::string iat = member_path(at, "indices");
    const Accessed idx = read_accessor(prim.indices, iat, {TINYGLTF_TYPE_SCALAR},
                                       {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                        TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT});
    list.reserve(idx.count);
    for (double v : idx.values) {
      if (v >= static_cast<double>(count)) {
        bad(iat, "index " + format_number(v) + " out of range (" + std::to_string(count) + " vertices)");
      }
      list.push_back(static_cast<uint32_t>(v));
    }
  } else {
    for (size_t i = 0; i < count; ++i) list.push_back(static_cast<uint32_t>(i));
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
  return tris;
}

void GltfReader::append_triangles(const std::vector<std::array<uint32_t, 3>>& tris, const Accessed& p,
                                  const Accessed& nrm, const Accessed& uv, int material, const glm::dmat4& world) {
  // Indexed: each vertex a triangle uses transformed once (a corner's values are what
  // transforming it at the corner would give), numbered in the accessor's order. Only the
  // used ones: primitives may share one large accessor, each drawing a part of it.
  const glm::dmat3 linear(world);
  const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(linear));
  const bool mirrors = glm::determinant(linear) < 0;
  const bool with_normals = !nrm.values.empty(), with_uv = !uv.values.empty();
  constexpr uint32_t UNUSED = 0xffffffffu;
  std::vector<uint32_t> number(p.count, UNUSED);
  for (const auto& t : tris) number[t[0]] = number[t[1]] = number[t[2]] = 0;
  uint32_t used = 0;
  for (uint32_t& n : number) n = n == UNUSED ? UNUSED : used++;
  out_.indexed = true;
  const size_t first = out_.positions.size(), first_normal = out_.normals.size(), first_uv = out_.uvs.size();
  const size_t corners = out_.position_index.size();
  out_.positions.resize(first + used);
  if (with_normals) out_.normals.resize(first_normal + used);
  if (with_uv) {
    if (out_.uvs.empty()) out_.uv_index.assign(corners, LocalMesh::NO_UV);  // the primitives before
    out_.uvs.resize(first_uv + used);
  }
  parallel_for_runs(p.count, ACCESSOR_RUN, st_.limits.threads, [&](size_t v) {
    if (number[v] == UNUSED) return;
    const size_t k = number[v];
    const double* q = &p.values[3 * v];
    out_.positions[first + k] = glm::dvec3(world * glm::dvec4(q[0], q[1], q[2], 1.0));
    if (with_normals) {
      const double* m = &nrm.values[3 * v];
      const glm::dvec3 n = normal_matrix * glm::dvec3(m[0], m[1], m[2]);
      const double len = glm::length(n);
      out_.normals[first_normal + k] = len > 0 && std::isfinite(len) ? n / len : glm::dvec3(0.0);  // 0: flat
    }
    if (with_uv) out_.uvs[first_uv + k] = glm::dvec2(uv.values[2 * v], 1.0 - uv.values[2 * v + 1]);  // v runs down
  });
  out_.position_index.resize(corners + 3 * tris.size());
  out_.normal_index.resize(corners + 3 * tris.size());
  if (!out_.uvs.empty()) out_.uv_index.resize(corners + 3 * tris.size());
  out_.material.resize(out_.material.size() + tris.size(), material);
  parallel_for_runs(tris.size(), ACCESSOR_RUN, st_.limits.threads, [&](size_t t) {
    const uint32_t order[3] = {tris[t][0], mirrors ? tris[t][2] : tris[t][1], mirrors ? tris[t][1] : tris[t][2]};
    for (size_t k = 0; k < 3; ++k) {
      const size_t at = corners + 3 * t + k;
      const uint32_t v = number[order[k]];
      out_.position_index[at] = static_cast<uint32_t>(first + v);
      out_.normal_index[at] = with_normals ? static_cast<uint32_t>(first_normal + v) : LocalMesh::NO_NORMAL;
      if (with_uv) {
        out_.uv_index[at] = static_cast<uint32_t>(first_uv + v);
      } else if (!out_.uvs.empty()) {
        out_.uv_index[at] = LocalMesh::NO_UV;
      }
    }
  });
}

}  // namespace abcube::detail::gltf
