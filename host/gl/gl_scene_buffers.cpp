// The scene's upload (the soup's buffers, the materials, the textures) and the draw calls
// every pass makes through them.
#include "gl/gl_scene_buffers.hpp"

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "base/error.hpp"
#include "gl/gl_targets.hpp"
#include "scene/texture.hpp"
#include "scene/tie_rule.hpp"

namespace abcube {

namespace {

// What the scene's vertex arrays hold besides the soup's positions and normals: a vertex's
// object and material (camera_groups.frag's Ids).
struct VertexIds {
  uint32_t object;
  uint32_t material;
};
static_assert(sizeof(VertexIds) == 8, "camera_groups.frag reads a vertex's ids as 2 words");

struct MaterialGpu {
  float color_ambient[4];
  float coefficients[4];
  float transmission[4];
};

struct LightGpu {
  float position[4];
  float color[4];
  float volumes[4];
};

float slot(const std::vector<int>& slots, size_t i) { return i < slots.size() ? float(slots[i]) : -1.f; }

}  // namespace

GLuint GlSceneBuffers::soup_buffer(const void* data, size_t bytes) {
  GLuint buffer = 0;
  glGenBuffers(1, &buffer);
  const GLsizeiptr size = static_cast<GLsizeiptr>(std::max<size_t>(bytes, 4));
  if (GLAD_GL_AMD_pinned_memory && bytes > 0 && pin_soup_) {
    check_gl("the GL state before the scene upload");  // so that an error below is the pinning's
    // The buffer is the memory at `data` from here on (read only: no pass writes it).
    glBindBuffer(GL_EXTERNAL_VIRTUAL_MEMORY_BUFFER_AMD, buffer);
    glBufferData(GL_EXTERNAL_VIRTUAL_MEMORY_BUFFER_AMD, static_cast<GLsizeiptr>(bytes), data, GL_STATIC_DRAW);
    glBindBuffer(GL_EXTERNAL_VIRTUAL_MEMORY_BUFFER_AMD, 0);
    if (glGetError() == GL_NO_ERROR) return buffer;
    // Refused (the driver takes no memory of this alignment or size): copied, as elsewhere.
    pinned_ = false;
    pin_soup_ = false;
    glDeleteBuffers(1, &buffer);
    glGenBuffers(1, &buffer);
  }
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glBufferData(GL_ARRAY_BUFFER, size, bytes > 0 ? data : nullptr, GL_STATIC_DRAW);
  if (bytes > 0) pinned_ = false;
  return buffer;
}

GlSceneBuffers::GlSceneBuffers(const SceneData& scene, const GlSceneOptions& options)
    : scene_(scene), pin_soup_(options.pin_soup), pinned_(options.pin_soup && GLAD_GL_AMD_pinned_memory) {
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size_);
  const double radius = max_distance_from(scene, scene.camera.position);
  near_ = default_near_distance(radius);

  // The soup's own arrays: positions, normals (per vertex) and each triangle's object and
  // material (read by scene.vert at the vertex's triangle, triangle_ids.glsl). With
  // GL_AMD_pinned_memory (Mesa's llvmpipe, where a GL buffer is process memory) the buffers are
  // the soup's memory, not a second copy of it; elsewhere they are copied as they are. The soup
  // outlives these buffers (the SceneData they read).
  const TriangleSoup& t = *scene.triangles;
  vertex_count_ = static_cast<GLsizei>(t.positions.size());
  glGenVertexArrays(1, &vao_);
  glBindVertexArray(vao_);
  positions_ = soup_buffer(t.positions.data(), t.positions.size() * sizeof(glm::vec3));
  normals_ = soup_buffer(t.normals.data(), t.normals.size() * sizeof(glm::vec3));
  object_ids_ = soup_buffer(t.object_id.data(), t.object_id.size() * sizeof(uint32_t));
  material_ids_ = soup_buffer(t.material_id.data(), t.material_id.size() * sizeof(uint32_t));
  glBindBuffer(GL_ARRAY_BUFFER, positions_);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
  glBindBuffer(GL_ARRAY_BUFFER, normals_);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
  for (GLuint a = 0; a < 2; ++a) glEnableVertexAttribArray(a);
  GLint vertex_blocks = 0, bindings = 0;
  GLint64 block = 0;
  glGetIntegerv(GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS, &vertex_blocks);
  glGetIntegerv(GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS, &bindings);
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block);
  triangle_ids_ = options.triangle_ids && vertex_blocks >= 3 && bindings > static_cast<GLint>(MATERIAL_IDS_BINDING) &&
                  t.triangle_count() * sizeof(uint32_t) <= static_cast<uint64_t>(block);
  if (!triangle_ids_) {
    upload_vertex_ids();
  } else {
    for (GLuint a = 2; a < 4; ++a) glDisableVertexAttribArray(a);
  }
  // Texture coordinates: their own buffer, straight from the soup, only when it has them.
  if (!t.uvs.empty()) {
    uv_vbo_ = soup_buffer(t.uvs.data(), t.uvs.size() * sizeof(glm::vec2));
    glBindBuffer(GL_ARRAY_BUFFER, uv_vbo_);
    glVertexAttribPointer(4, 2, GL_FLOAT, GL_FALSE, sizeof(glm::vec2), nullptr);
    glEnableVertexAttribArray(4);
  } else {
    glDisableVertexAttribArray(4);
    glVertexAttrib2f(4, 0.f, 0.f);
  }
  // The planar reflectors' ids (attribute 5) are gl_planar_mirrors.cpp's. The generic values
  // of the arrays left off: no reflector, no reversal.
  glDisableVertexAttribArray(5);
  glVertexAttribI1ui(5, 0);
  glVertexAttribI1ui(6, 0);
  upload_materials();
  glGenBuffers(1, &lights_);
}

// Each vertex carries its ids (8 bytes), copied a chunk at a time, so that the peak never
// holds a whole array of them beside the GL buffer.
void GlSceneBuffers::upload_vertex_ids() {
  const TriangleSoup& t = *scene_.triangles;
  constexpr size_t CHUNK = 3 * 16384;  // vertices
  glGenBuffers(1, &vertex_ids_);
  glBindBuffer(GL_ARRAY_BUFFER, vertex_ids_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(std::max<size_t>(t.positions.size(), 1) * sizeof(VertexIds)),
               nullptr, GL_STATIC_DRAW);
  std::vector<VertexIds> chunk;
  for (size_t first = 0; first < t.positions.size(); first += CHUNK) {
    chunk.resize(std::min(CHUNK, t.positions.size() - first));
    for (size_t i = 0; i < chunk.size(); ++i) {
      const size_t triangle = (first + i) / 3;
      chunk[i] = {t.object_id[triangle], t.material_id[triangle]};
    }
    glBufferSubData(GL_ARRAY_BUFFER, static_cast<GLintptr>(first * sizeof(VertexIds)),
                    static_cast<GLsizeiptr>(chunk.size() * sizeof(VertexIds)), chunk.data());
  }
  const auto offset = [](size_t bytes) { return reinterpret_cast<const void*>(bytes); };
  glVertexAttribIPointer(2, 1, GL_UNSIGNED_INT, sizeof(VertexIds), offset(offsetof(VertexIds, object)));
  glVertexAttribIPointer(3, 1, GL_UNSIGNED_INT, sizeof(VertexIds), offset(offsetof(VertexIds, material)));
  for (GLuint a = 2; a < 4; ++a) glEnableVertexAttribArray(a);
}

void GlSceneBuffers::upload_materials() {
  const std::vector<float> texture_codes = upload_textures();
  std::vector<MaterialGpu> materials;
  for (size_t i = 0; i < scene_.materials.size(); ++i) {
    const Material& m = scene_.materials[i];
    materials.push_back({{float(m.color.r), float(m.color.g), float(m.color.b), float(m.ambient)},
                         {float(m.diffuse), float(m.specular), float(m.shininess), float(m.reflect)},
                         {float(m.transmit), float(m.ior), float(m.opacity), texture_codes[i]}});
  }
  if (materials.empty()) materials.push_back({});
  glGenBuffers(1, &materials_);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, materials_);
  glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(materials.size() * sizeof(MaterialGpu)),
               materials.data(), GL_STATIC_DRAW);
}

std::vector<float> GlSceneBuffers::upload_textures() {
  std::vector<float> code(scene_.materials.size(), -1.f);
  if (!scene_.textures) return code;
  const std::vector<TextureImage>& images = scene_.textures->images();
  // Size classes in the order the images come; each image's array and layer.
  std::vector<std::pair<int, int>> sizes;
  std::vector<std::vector<size_t>> members;
  std::vector<int> array_of(images.size()), layer_of(images.size());
  for (size_t i = 0; i < images.size(); ++i) {
    const std::pair<int, int> size{images[i].width, images[i].height};
    size_t a = static_cast<size_t>(std::find(sizes.begin(), sizes.end(), size) - sizes.begin());
    if (a == sizes.size()) {
      sizes.push_back(size);
      members.emplace_back();
    }
    array_of[i] = static_cast<int>(a);
    layer_of[i] = static_cast<int>(members[a].size());
    members[a].push_back(i);
  }
  if (sizes.size() > static_cast<size_t>(MAX_TEXTURE_ARRAYS)) {
    throw RuntimeFailure("the GL passes take textures of at most " + std::to_string(MAX_TEXTURE_ARRAYS) +
                         " different sizes, the scene has " + std::to_string(sizes.size()));
  }
  texture_arrays_.assign(sizes.size(), 0);
  glGenTextures(static_cast<GLsizei>(sizes.size()), texture_arrays_.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  std::vector<float> flipped;
  for (size_t a = 0; a < sizes.size(); ++a) {
    const int w = sizes[a].first, h = sizes[a].second;
    if (w > max_size_ || h > max_size_) {
      throw RuntimeFailure("texture of " + std::to_string(w) + "x" + std::to_string(h) +
                           " exceeds GL_MAX_TEXTURE_SIZE " + std::to_string(max_size_));
    }
    int levels = 1;
    while ((std::max(w, h) >> levels) > 0) ++levels;
    glBindTexture(GL_TEXTURE_2D_ARRAY, texture_arrays_[a]);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, levels, GL_RGB32F, w, h, static_cast<GLsizei>(members[a].size()));
    for (size_t k = 0; k < members[a].size(); ++k) {
      const TextureImage& image = images[members[a][k]];
      // GL's row 0 is t = 0, the image's bottom (v = 0): rows upside down.
      flipped.resize(image.rgb.size());
      const size_t row = 3 * static_cast<size_t>(w);
      for (int y = 0; y < h; ++y) {
        std::memcpy(&flipped[static_cast<size_t>(h - 1 - y) * row], &image.rgb[static_cast<size_t>(y) * row],
                    row * sizeof(float));
      }
      glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, static_cast<GLint>(k), w, h, 1, GL_RGB, GL_FLOAT, flipped.data());
    }
    glGenerateMipmap(GL_TEXTURE_2D_ARRAY);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_REPEAT);
  }
  glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
  for (size_t m = 0; m < code.size(); ++m) {
    const int image = scene_.textures->image_of(static_cast<uint32_t>(m));
    if (image >= 0) {
      code[m] = float(array_of[static_cast<size_t>(image)] + MAX_TEXTURE_ARRAYS * layer_of[static_cast<size_t>(image)]);
    }
  }
  check_gl("texture upload");
  return code;
}

GlSceneBuffers::~GlSceneBuffers() {
  glDeleteTextures(static_cast<GLsizei>(texture_arrays_.size()), texture_arrays_.data());
  const GLuint buffers[] = {positions_,  normals_, object_ids_, material_ids_,
                            vertex_ids_, uv_vbo_,  materials_,  lights_};
  glDeleteBuffers(8, buffers);
  glDeleteVertexArrays(1, &vao_);
}

void GlSceneBuffers::upload_lights(const glm::dvec3& center, const std::vector<int>& shadow_layer,
                                   const std::vector<int>& volume_bit, const std::vector<int>& translucent_bit) const {
  std::vector<LightGpu> lights;
  for (size_t i = 0; i < scene_.lights.size(); ++i) {
    const PointLight& l = scene_.lights[i];
    const glm::dvec3 p = l.position - center;
    lights.push_back({{float(p.x), float(p.y), float(p.z), slot(shadow_layer, i)},
                      {float(l.color.r), float(l.color.g), float(l.color.b), slot(volume_bit, i)},
                      {slot(translucent_bit, i), 0.f, 0.f, 0.f}});
  }
  if (lights.empty()) lights.push_back({});
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, lights_);
  glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(lights.size() * sizeof(LightGpu)), lights.data(),
               GL_DYNAMIC_DRAW);
}

void GlSceneBuffers::bind_textures(const GlProgram& program, bool level0) const {
  GLint texture_units[MAX_TEXTURE_ARRAYS];
  for (int k = 0; k < MAX_TEXTURE_ARRAYS; ++k) {
    texture_units[k] = static_cast<GLint>(TEXTURE_UNIT) + k;
    glActiveTexture(GL_TEXTURE0 + TEXTURE_UNIT + static_cast<GLenum>(k));
    glBindTexture(GL_TEXTURE_2D_ARRAY,
                  static_cast<size_t>(k) < texture_arrays_.size() ? texture_arrays_[static_cast<size_t>(k)] : 0);
  }
  glUniform1iv(program.uniform("u_textures"), MAX_TEXTURE_ARRAYS, texture_units);
  glUniform1i(program.uniform("u_texture_level0"), level0);
}

std::vector<const char*> GlSceneBuffers::vertex_stage(const char* before) const {
  std::vector<const char*> files;
  if (before) files.push_back(before);
  if (triangle_ids_) files.push_back("triangle_ids.glsl");
  files.push_back("scene.vert");
  return files;
}

void GlSceneBuffers::set_view(const GlProgram& program, const glm::mat4& clip, const MirrorView& view,
                              bool ties) const {
  program.use();
  if (triangle_ids_) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, OBJECT_IDS_BINDING, object_ids_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MATERIAL_IDS_BINDING, material_ids_);
  }
  // `clip` has the eye at the origin (scene.vert subtracts it); a virtual view's reflections
  // then act on the relative vertex by their linear part alone (M (p) - E = R (p - eye), the
  // view's eye being the camera's unfolded through them).
  const glm::mat4 clip_model = view.level == 0 ? clip : glm::mat4(glm::dmat4(clip) * view.linear());
  glUniformMatrix4fv(program.uniform("u_clip"), 1, GL_FALSE, &clip_model[0][0]);
  // The clip plane relative to the eye: n . (rel + eye) + d.
  const double offset = view.plane.w + glm::dot(glm::dvec3(view.plane), view.eye);
  glUniform4f(program.uniform("u_clip_plane"), float(view.plane.x), float(view.plane.y), float(view.plane.z),
              view.level == 0 ? 1.f : float(offset));
  glUniform1ui(program.uniform("u_skip_portal"), view.skip);
  glUniform3d(program.uniform("u_center"), view.eye.x, view.eye.y, view.eye.z);
  glUniform1f(program.uniform("u_tie_step"), ties ? float(gl_tie_step(scene_.objects.size())) : 0.f);
  glUniform3f(program.uniform("u_ambient"), float(scene_.ambient.r), float(scene_.ambient.g), float(scene_.ambient.b));
  glUniform1i(program.uniform("u_light_count"), static_cast<GLint>(scene_.lights.size()));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MATERIALS_BINDING, materials_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LIGHTS_BINDING, lights_);
}

void GlSceneBuffers::draw_scene(const GlProgram& program, const glm::mat4& clip, const MirrorView& view,
                                bool ties) const {
  set_view(program, clip, view, ties);
  glBindVertexArray(vao_);
  if (vertex_count_ > 0) glDrawArrays(GL_TRIANGLES, 0, vertex_count_);
}

void GlSceneBuffers::draw(const GlProgram& program, const glm::mat4& clip, const glm::dvec3& center, bool ties) const {
  MirrorView view;
  view.eye = center;
  draw_scene(program, clip, view, ties);
}

}  // namespace abcube
