// GlScene's upload (the soup's buffers, the materials, the textures), its framebuffers and
// draw calls, and the passes of no technique of their own: the cube distance prepass, the
// camera's object ids, the Z-buffer colour of cube faces and of the camera view.
#include "gl/gl_passes.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "raster/cube_map.hpp"
#include "base/samples.hpp"
#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "gl/gl_passes_internal.hpp"
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

}  // namespace

GLuint GlScene::soup_buffer(const void* data, size_t bytes) {
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

GlScene::GlScene(const SceneData& scene, const GlSceneOptions& options)
    : scene_(scene), pin_soup_(options.pin_soup), pinned_(options.pin_soup && GLAD_GL_AMD_pinned_memory) {
  const Clock::time_point t0 = Clock::now();
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size_);
  const double radius = max_distance_from(scene, scene.camera.position);
  near_ = default_near_distance(radius);

  // The soup's own arrays: positions, normals (per vertex) and each triangle's object and
  // material (read by scene.vert at the vertex's triangle, triangle_ids.glsl). With
  // GL_AMD_pinned_memory (Mesa's llvmpipe, where a GL buffer is process memory) the buffers are
  // the soup's memory, not a second copy of it; elsewhere they are copied as they are. The soup
  // outlives this GlScene (the SceneData it reads).
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
    // Each vertex carries its ids (8 bytes), copied a chunk at a time, so that the peak
    // never holds a whole array of them beside the GL buffer.
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

  // Planar reflectors (the exact camera pass): a reflector id per vertex, and each one's
  // triangles as a range of an index buffer, both kept with the vertex array.
  reflectors_ = find_planar_reflectors(scene);
  if (!reflectors_.reflectors.empty()) {
    std::vector<uint32_t> ids(t.positions.size()), indices;
    for (size_t v = 0; v < ids.size(); ++v) ids[v] = reflectors_.reflector_of_triangle[v / 3];
    glGenBuffers(1, &portal_vbo_);
    glBindBuffer(GL_ARRAY_BUFFER, portal_vbo_);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(ids.size() * sizeof(uint32_t)), ids.data(), GL_STATIC_DRAW);
    glVertexAttribIPointer(5, 1, GL_UNSIGNED_INT, sizeof(uint32_t), nullptr);
    glEnableVertexAttribArray(5);
    for (const PlanarReflector& r : reflectors_.reflectors) {
      portal_ranges_.emplace_back(indices.size(), 3 * r.triangles.size());
      for (const uint32_t tri : r.triangles) {
        for (uint32_t k = 0; k < 3; ++k) indices.push_back(3 * tri + k);
      }
    }
    glGenBuffers(1, &portal_ebo_);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, portal_ebo_);  // kept by the vertex array
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(uint32_t)), indices.data(),
                 GL_STATIC_DRAW);
  } else {
    glDisableVertexAttribArray(5);
  }
  glVertexAttribI1ui(5, 0);  // the generic values of the arrays left off: no reflector, no reversal
  glVertexAttribI1ui(6, 0);
  const std::vector<float> texture_codes = upload_textures();
  std::vector<MaterialGpu> materials;
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    materials.push_back({{float(m.color.r), float(m.color.g), float(m.color.b), float(m.ambient)},
                         {float(m.diffuse), float(m.specular), float(m.shininess), float(m.reflect)},
                         {float(m.transmit), float(m.ior), float(m.opacity), texture_codes[i]}});
  }
  if (materials.empty()) materials.push_back({});
  glGenBuffers(1, &materials_);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, materials_);
  glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(materials.size() * sizeof(MaterialGpu)),
               materials.data(), GL_STATIC_DRAW);
  glGenBuffers(1, &lights_);

  distance_program_ = std::make_unique<GlProgram>(scene_vertex_stage(), std::vector<const char*>{"cube_distance.frag"});
  phong_program_ = std::make_unique<GlProgram>(
      scene_vertex_stage(), std::vector<const char*>{"common_scene.glsl", "common_shading.glsl", "phong.frag"});
  shadow_program_ = std::make_unique<GlProgram>(scene_vertex_stage(),
                                                std::vector<const char*>{"common_scene.glsl", "shadow_caster.frag"});
  // Every sampler of the phong program on a unit of its own type (two sampler types on one
  // unit is an error at draw time, even when one is never read).
  phong_program_->use();
  glUniform1i(phong_program_->uniform("u_previous"), static_cast<GLint>(CAMERA_PREVIOUS_UNIT));
  glUniform1i(phong_program_->uniform("u_volume_counts"), static_cast<GLint>(VOLUME_COUNT_UNIT));
  glFinish();
  check_gl("scene upload");
  timings_.upload_ms = ms_since(t0);
}

std::vector<float> GlScene::upload_textures() {
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

GlScene::~GlScene() {
  target_.reset();
  exact_buffers_.reset();
  visibility_.reset();
  glDeleteBuffers(1, &portal_vbo_);
  glDeleteBuffers(1, &portal_ebo_);
  glDeleteBuffers(1, &recursed_);
  glDeleteBuffers(static_cast<GLsizei>(volume_caps_.size()), volume_caps_.data());
  glDeleteBuffers(1, &clipped_vbo_);
  glDeleteVertexArrays(1, &clipped_vao_);
  glDeleteTextures(static_cast<GLsizei>(texture_arrays_.size()), texture_arrays_.data());
  glDeleteBuffers(1, &uv_vbo_);
  const GLuint textures[] = {shadow_maps_, environment_};
  glDeleteTextures(2, textures);
  glDeleteTextures(static_cast<GLsizei>(shadow_peels_.size()), shadow_peels_.data());
  glDeleteRenderbuffers(1, &lookup_depth_);
  glDeleteFramebuffers(1, &lookup_fbo_);
  const GLuint scene_buffers[] = {positions_, normals_, object_ids_, material_ids_, vertex_ids_};
  glDeleteBuffers(5, scene_buffers);
  glDeleteBuffers(1, &materials_);
  glDeleteBuffers(1, &lights_);
  glDeleteVertexArrays(1, &vao_);
}

GlScene::Target& GlScene::target(int width, int height, bool distance_pass) {
  if (width < 1 || height < 1 || width > max_size_ || height > max_size_) {
    throw RuntimeFailure("GL target " + std::to_string(width) + "x" + std::to_string(height) +
                         " exceeds GL_MAX_TEXTURE_SIZE " + std::to_string(max_size_));
  }
  if (!target_ || target_->width != width || target_->height != height || target_->distance_pass != distance_pass) {
    target_.reset();
    target_ = std::make_unique<Target>(width, height, distance_pass);
  }
  return *target_;
}

void GlScene::upload_lights(const glm::dvec3& center) {
  std::vector<LightGpu> lights;
  for (size_t i = 0; i < scene_.lights.size(); ++i) {
    const PointLight& l = scene_.lights[i];
    const glm::dvec3 p = l.position - center;
    const float layer = i < shadow_layer_.size() ? float(shadow_layer_[i]) : -1.f;
    // The shadow-volume counts of its opaque and translucent blockers (the exact camera pass).
    const float bit = i < volume_bit_.size() ? float(volume_bit_[i]) : -1.f;
    const float translucent = i < translucent_bit_.size() ? float(translucent_bit_[i]) : -1.f;
    lights.push_back({{float(p.x), float(p.y), float(p.z), layer},
                      {float(l.color.r), float(l.color.g), float(l.color.b), bit},
                      {translucent, 0.f, 0.f, 0.f}});
  }
  if (lights.empty()) lights.push_back({});
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, lights_);
  glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(lights.size() * sizeof(LightGpu)), lights.data(),
               GL_DYNAMIC_DRAW);
}

void GlScene::draw(const GlProgram& program, const glm::mat4& clip, const glm::dvec3& center) {
  MirrorView view;
  view.eye = center;
  draw_scene(program, clip, view);
}

void GlScene::draw_scene(const GlProgram& program, const glm::mat4& clip, const MirrorView& view) {
  set_view(program, clip, view);
  glBindVertexArray(vao_);
  if (vertex_count_ > 0) glDrawArrays(GL_TRIANGLES, 0, vertex_count_);
}

void GlScene::draw_reflector(const GlProgram& program, const glm::mat4& clip, const MirrorView& view, size_t r) {
  set_view(program, clip, view);
  glBindVertexArray(vao_);
  const auto [first, count] = portal_ranges_[r];
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(count), GL_UNSIGNED_INT,
                 reinterpret_cast<const void*>(first * sizeof(uint32_t)));
}

std::vector<const char*> GlScene::scene_vertex_stage(const char* before) const {
  std::vector<const char*> files;
  if (before) files.push_back(before);
  if (triangle_ids_) files.push_back("triangle_ids.glsl");
  files.push_back("scene.vert");
  return files;
}

void GlScene::set_view(const GlProgram& program, const glm::mat4& clip, const MirrorView& view) {
  const glm::dvec3& center = view.eye;
  program.use();
  if (triangle_ids_) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, OBJECT_IDS_BINDING, object_ids_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MATERIAL_IDS_BINDING, material_ids_);
  }
  // `clip` has the eye at the origin (scene.vert subtracts it); a virtual view's reflections
  // then act on the relative vertex by their linear part alone (M (p) - E = R (p - eye), the
  // view's eye being the camera's unfolded through them).
  glm::dmat4 linear = view.model;
  linear[3] = glm::dvec4(0.0, 0.0, 0.0, 1.0);
  const glm::mat4 clip_model = view.level == 0 ? clip : glm::mat4(glm::dmat4(clip) * linear);
  glUniformMatrix4fv(program.uniform("u_clip"), 1, GL_FALSE, &clip_model[0][0]);
  // The clip plane relative to the eye: n . (rel + eye) + d.
  const double offset = view.plane.w + glm::dot(glm::dvec3(view.plane), view.eye);
  glUniform4f(program.uniform("u_clip_plane"), float(view.plane.x), float(view.plane.y), float(view.plane.z),
              view.level == 0 ? 1.f : float(offset));
  glUniform1ui(program.uniform("u_skip_portal"), view.skip);
  glUniform3d(program.uniform("u_center"), center.x, center.y, center.z);
  // tie_rule.hpp; not in the shadow passes, whose casters all count and whose translucent
  // peels order equal depths by triangle (shadow_caster.frag), GL_GREATER's draw order.
  const bool ties = &program != shadow_program_.get();
  glUniform1f(program.uniform("u_tie_step"), ties ? float(gl_tie_step(scene_.objects.size())) : 0.f);
  glUniform3f(program.uniform("u_ambient"), float(scene_.ambient.r), float(scene_.ambient.g), float(scene_.ambient.b));
  glUniform1i(program.uniform("u_light_count"), static_cast<GLint>(scene_.lights.size()));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, materials_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, lights_);
}

// Binds the shadow maps (unit 1) and, if asked and built, the environment map (unit 2).
void GlScene::bind_lookups(const GlProgram& program, bool with_environment) {
  program.use();
  const bool shadows = shadow_maps_ != 0;
  glUniform1i(program.uniform("u_shadows"), shadows);
  glUniform1i(program.uniform("u_shadow_maps"), 1);
  glUniform1f(program.uniform("u_shadow_texel"), shadows ? float(2.0 / shadow_n_) : 0.f);
  glUniform1f(program.uniform("u_shadow_bias_texels"), float(SHADOW_BIAS_TEXELS));
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, shadow_maps_);
  glUniform1i(program.uniform("u_shadow_peels"), shadows ? static_cast<GLint>(shadow_peels_.size()) : 0);
  GLint units[MAX_SHADOW_PEELS];
  for (int k = 0; k < MAX_SHADOW_PEELS; ++k) {
    units[k] = static_cast<GLint>(PEEL_UNIT) + k;
    glActiveTexture(GL_TEXTURE0 + PEEL_UNIT + static_cast<GLenum>(k));
    glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY,
                  static_cast<size_t>(k) < shadow_peels_.size() ? shadow_peels_[static_cast<size_t>(k)] : 0);
  }
  glUniform1iv(program.uniform("u_shadow_peel_maps"), MAX_SHADOW_PEELS, units);
  const bool environment = with_environment && environment_ != 0;
  glUniform1i(program.uniform("u_environment"), environment);
  glUniform1i(program.uniform("u_lookup"), lookup_ == EnvmapLookup::bisector   ? 1
                                           : lookup_ == EnvmapLookup::position ? 2
                                                                               : 0);
  glUniform1i(program.uniform("u_fresnel"), fresnel_);
  glUniform1i(program.uniform("u_environment_map"), 2);
  GLint texture_units[MAX_TEXTURE_ARRAYS];
  for (int k = 0; k < MAX_TEXTURE_ARRAYS; ++k) {
    texture_units[k] = static_cast<GLint>(TEXTURE_UNIT) + k;
    glActiveTexture(GL_TEXTURE0 + TEXTURE_UNIT + static_cast<GLenum>(k));
    glBindTexture(GL_TEXTURE_2D_ARRAY,
                  static_cast<size_t>(k) < texture_arrays_.size() ? texture_arrays_[static_cast<size_t>(k)] : 0);
  }
  glUniform1iv(program.uniform("u_textures"), MAX_TEXTURE_ARRAYS, texture_units);
  glUniform1i(program.uniform("u_texture_level0"), texture_level0_);
  glActiveTexture(GL_TEXTURE2);
  glBindTexture(GL_TEXTURE_CUBE_MAP, environment ? environment_ : 0);
  glActiveTexture(GL_TEXTURE0);
}

void GlScene::cube_distance(const glm::dvec3& center, int n, CubeImage* distance, CubeIds* ids, int n_t) {
  const int h = n_t > 0 ? n_t : n;
  Target& t = target(n, h, true);
  *distance = CubeImage(n, 1);
  if (ids) ids->n = n;
  for (int face = 0; face < CUBE_FACES; ++face) {
    check_deadline();
    Clock::time_point t0 = Clock::now();
    t.clear(scene_.background);
    draw(*distance_program_, face_clip_matrix(face, glm::dvec3(0.0), near_), center);
    glFinish();
    timings_.cube_distance_ms += ms_since(t0);
    t0 = Clock::now();
    Image& img = distance->faces[static_cast<size_t>(face)];
    img = Image(n, h, 1);
    t.read(0, GL_RED, GL_FLOAT, img.data.data());
    if (ids) {
      auto& f = ids->faces[static_cast<size_t>(face)];
      f.assign(static_cast<size_t>(n) * h, NO_OBJECT);
      t.read(1, GL_RED_INTEGER, GL_UNSIGNED_INT, f.data());
    }
    timings_.readback_ms += ms_since(t0);
  }
  check_gl("cube distance prepass");
}

std::vector<uint32_t> GlScene::camera_objects(const Camera& camera) {
  const int64_t full_w = int64_t{camera.width} * MASK_COLUMNS, full_h = int64_t{camera.height} * MASK_ROWS;
  const SampleTiles tiles(full_w, full_h, max_size_);
  const int tile_w = tiles.tile_w, tile_h = tiles.tile_h;
  Target& t = target(tiles.target_w(), tiles.target_h(), true);
  const glm::mat4 clip = relative_camera_clip(camera, near_);
  std::vector<uint32_t> out(static_cast<size_t>(full_w * full_h), NO_OBJECT),
      tile_ids(size_t(tiles.target_w()) * size_t(tiles.target_h()));
  for (int64_t y0 = 0; y0 < full_h; y0 += tile_h) {
    for (int64_t x0 = 0; x0 < full_w; x0 += tile_w) {
      check_deadline();
      t.clear(scene_.background);
      draw(*distance_program_, tiles.matrix(x0, y0) * clip, camera.position);
      t.read(1, GL_RED_INTEGER, GL_UNSIGNED_INT, tile_ids.data());
      // GL's row 0 is the bottom; the grid's row 0 is the top.
      for (int64_t gy = 0; gy < tile_h && y0 + gy < full_h; ++gy) {
        for (int64_t gx = 0; gx < tile_w && x0 + gx < full_w; ++gx) {
          out[static_cast<size_t>((full_h - 1 - (y0 + gy)) * full_w + x0 + gx)] = tile_ids[tiles.index(gx, gy)];
        }
      }
    }
  }
  check_gl("camera object ids");
  return out;
}

CubeImage GlScene::cube_color(const glm::dvec3& center, int n) {
  Target& t = target(n, n, false);
  CubeImage out(n, 3);
  upload_lights(center);
  bind_lookups(*phong_program_, false);
  std::vector<float> rgba(static_cast<size_t>(n) * n * 4);
  for (int face = 0; face < CUBE_FACES; ++face) {
    check_deadline();
    Clock::time_point t0 = Clock::now();
    t.clear(scene_.background);
    draw(*phong_program_, face_clip_matrix(face, glm::dvec3(0.0), near_), center);
    glFinish();
    timings_.cube_color_ms += ms_since(t0);
    t0 = Clock::now();
    t.read(0, GL_RGBA, GL_FLOAT, rgba.data());
    Image& img = out.faces[static_cast<size_t>(face)];
    for (size_t p = 0; p < static_cast<size_t>(n) * n; ++p) {
      for (int c = 0; c < 3; ++c) img.data[p * 3 + c] = rgba[p * 4 + c];
    }
    timings_.readback_ms += ms_since(t0);
  }
  check_gl("cube colour pass");
  return out;
}

Image GlScene::camera_color(const Camera& camera, CameraSamples samples) {
  const bool mask = samples == CameraSamples::mask_4x8;
  if (mask && plan_exact_camera()) return camera_color_exact(camera);
  const int64_t sx = mask ? MASK_COLUMNS : 1, sy = mask ? MASK_ROWS : 1;
  const int64_t full_w = camera.width * sx, full_h = camera.height * sy;
  const SampleTiles tiles(full_w, full_h, max_size_);
  const int tile_w = tiles.tile_w, tile_h = tiles.tile_h;
  Target& t = target(tiles.target_w(), tiles.target_h(), false);
  upload_lights(camera.position);
  bind_lookups(*phong_program_, true);
  const glm::mat4 clip = relative_camera_clip(camera, near_);
  // Coverage transparency (rule "opacity"): the view is peeled front to back, each layer
  // blended under the ones before it, C += T op c, T *= 1 - op, the background last.
  bool transparent = false;
  for (const uint32_t id : scene_.triangles->material_id)
    transparent = transparent || scene_.materials[id].opacity < 1.0;
  const size_t tile_samples = static_cast<size_t>(tiles.target_w()) * static_cast<size_t>(tiles.target_h());
  std::vector<float> rgba(tile_samples * 4);
  std::vector<double> colour(tile_samples * 3), through(tile_samples);
  std::vector<double> sum(static_cast<size_t>(camera.width) * static_cast<size_t>(camera.height) * 3, 0.0);
  GLuint previous = 0, query = 0;
  if (transparent) {
    glGenTextures(1, &previous);
    glBindTexture(GL_TEXTURE_2D, previous);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RG32F, tiles.target_w(), tiles.target_h());
    glGenQueries(1, &query);
    phong_program_->use();
    glUniform1i(phong_program_->uniform("u_previous"), static_cast<GLint>(CAMERA_PREVIOUS_UNIT));
  }
  const glm::dvec3 bg = scene_.background;
  camera_layers_ = 0;
  camera_layers_capped_ = false;
  // Tile (x0, y0) in GL window coordinates of the full sample grid (y up).
  for (int64_t y0 = 0; y0 < full_h; y0 += tile_h) {
    for (int64_t x0 = 0; x0 < full_w; x0 += tile_w) {
      check_deadline();
      const glm::mat4 tile = tiles.matrix(x0, y0);
      std::fill(colour.begin(), colour.end(), 0.0);
      std::fill(through.begin(), through.end(), 1.0);
      for (int layer = 0; layer < (transparent ? MAX_CAMERA_LAYERS : 1); ++layer) {
        Clock::time_point t0 = Clock::now();
        phong_program_->use();
        glUniform1i(phong_program_->uniform("u_peel"), layer);
        if (layer > 0) {
          glCopyImageSubData(t.color1, GL_TEXTURE_2D, 0, 0, 0, 0, previous, GL_TEXTURE_2D, 0, 0, 0, 0, tiles.target_w(),
                             tiles.target_h(), 1);
          glActiveTexture(GL_TEXTURE0 + CAMERA_PREVIOUS_UNIT);
          glBindTexture(GL_TEXTURE_2D, previous);
          glActiveTexture(GL_TEXTURE0);
        }
        t.clear(bg);
        if (transparent) {
          const float none[4] = {0, 0, 0, 0};  // alpha 0: no surface at this sample
          glClearBufferfv(GL_COLOR, 0, none);
          glBeginQuery(GL_ANY_SAMPLES_PASSED, query);
        }
        draw(*phong_program_, tile * clip, camera.position);
        GLuint drew = 1;
        if (transparent) {
          glEndQuery(GL_ANY_SAMPLES_PASSED);
          glGetQueryObjectuiv(query, GL_QUERY_RESULT, &drew);
        }
        glFinish();
        timings_.camera_ms += ms_since(t0);
        if (!drew) break;
        camera_layers_ = std::max(camera_layers_, layer + 1);
        camera_layers_capped_ = camera_layers_capped_ || (transparent && layer + 1 == MAX_CAMERA_LAYERS);
        t0 = Clock::now();
        t.read(0, GL_RGBA, GL_FLOAT, rgba.data());
        for (size_t k = 0; k < tile_samples; ++k) {
          const double a = transparent ? rgba[4 * k + 3] : 1.0;
          for (int c = 0; c < 3; ++c)
            colour[3 * k + static_cast<size_t>(c)] += through[k] * a * rgba[4 * k + static_cast<size_t>(c)];
          through[k] *= 1.0 - a;
        }
        timings_.readback_ms += ms_since(t0);
      }
      // GL's row 0 is the bottom; the image's row 0 is the top.
      for (int64_t gy = 0; gy < tile_h && y0 + gy < full_h; ++gy) {
        const size_t row = static_cast<size_t>((full_h - 1 - (y0 + gy)) / sy);
        for (int64_t gx = 0; gx < tile_w && x0 + gx < full_w; ++gx) {
          const size_t k = tiles.index(gx, gy);
          double* dst = &sum[(row * static_cast<size_t>(camera.width) + static_cast<size_t>((x0 + gx) / sx)) * 3];
          for (int c = 0; c < 3; ++c) dst[c] += colour[3 * k + static_cast<size_t>(c)] + through[k] * bg[c];
        }
      }
    }
  }
  if (transparent) {
    phong_program_->use();
    glUniform1i(phong_program_->uniform("u_peel"), 0);
    glDeleteTextures(1, &previous);
    glDeleteQueries(1, &query);
  }
  Image out(camera.width, camera.height, 3);
  const double samples_per_pixel = double(sx * sy);
  for (size_t k = 0; k < sum.size(); ++k) out.data[k] = static_cast<float>(sum[k] / samples_per_pixel);
  check_gl("camera pass");
  return out;
}

}  // namespace abcube
