#include "gl/gl_passes.hpp"

#include <chrono>
#include <cmath>
#include <algorithm>
#include <cstring>
#include <vector>

#include "raster/cube_map.hpp"
#include "base/error.hpp"
#include "base/timer.hpp"

namespace abcube {

namespace {


struct Vertex {
  float position[3];
  float normal[3];
  uint32_t object;
  uint32_t material;
};

struct MaterialGpu {
  float color_ambient[4];
  float coefficients[4];
  float transmission[4];
};

struct LightGpu {
  float position[4];
  float color[4];
};

// The state every pass relies on: infinite reversed-Z (cube_map.hpp: depth in [0, 1], 1 at
// the near plane, GL_GREATER), no culling (the map holds every surface), no blending.
void set_pass_state() {
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
}

}  // namespace

// One framebuffer: distance (R32F) + object id (R32UI), or colour (RGBA32F); depth 32F.
struct GlScene::Target {
  int width = 0, height = 0;
  bool distance_pass = false;
  GLuint fbo = 0, color0 = 0, color1 = 0, depth = 0;

  Target(int w, int h, bool distance) : width(w), height(h), distance_pass(distance) {
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    auto make = [&](GLenum format, GLenum attachment) {
      GLuint tex = 0;
      glGenTextures(1, &tex);
      glBindTexture(GL_TEXTURE_2D, tex);
      glTexStorage2D(GL_TEXTURE_2D, 1, format, w, h);
      glFramebufferTexture2D(GL_FRAMEBUFFER, attachment, GL_TEXTURE_2D, tex, 0);
      return tex;
    };
    color0 = make(distance ? GL_R32F : GL_RGBA32F, GL_COLOR_ATTACHMENT0);
    if (distance) color1 = make(GL_R32UI, GL_COLOR_ATTACHMENT1);
    depth = make(GL_DEPTH_COMPONENT32F, GL_DEPTH_ATTACHMENT);
    const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(distance ? 2 : 1, buffers);
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      throw RuntimeFailure("framebuffer " + std::to_string(w) + "x" + std::to_string(h) +
                           " incomplete (status " + std::to_string(status) + ")");
    }
  }
  ~Target() {
    const GLuint textures[] = {color0, color1, depth};
    glDeleteTextures(3, textures);
    glDeleteFramebuffers(1, &fbo);
  }

  // Binds the target, sets the state every pass relies on, and clears it.
  void clear(const glm::dvec3& background) const {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, width, height);
    set_pass_state();
    const float zero_depth = 0.f;  // reversed Z: 0 is infinitely far
    glClearBufferfv(GL_DEPTH, 0, &zero_depth);
    if (distance_pass) {
      const float far[4] = {NO_DISTANCE, 0, 0, 0};
      const GLuint none[4] = {NO_OBJECT, 0, 0, 0};
      glClearBufferfv(GL_COLOR, 0, far);
      glClearBufferuiv(GL_COLOR, 1, none);
    } else {
      const float bg[4] = {float(background.x), float(background.y), float(background.z), 1.f};
      glClearBufferfv(GL_COLOR, 0, bg);
    }
  }

  // Reads attachment `index` into `out` (`components` values per texel, GL row order).
  void read(int index, GLenum format, GLenum type, void* out) const {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glReadBuffer(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(index));
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, format, type, out);
  }
};

GlScene::GlScene(const SceneData& scene) : scene_(scene) {
  const Clock::time_point t0 = Clock::now();
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size_);
  const double radius = max_distance_from(scene, scene.camera.position);
  near_ = default_near_distance(radius);

  // Uploaded in chunks: a copy of the whole vertex array beside the soup and the GL
  // buffer cost 96 bytes a triangle at the peak.
  const TriangleSoup& t = *scene.triangles;
  constexpr size_t CHUNK = 3 * 16384;  // vertices
  vertex_count_ = static_cast<GLsizei>(t.positions.size());
  glGenVertexArrays(1, &vao_);
  glBindVertexArray(vao_);
  glGenBuffers(1, &vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(t.positions.size() * sizeof(Vertex)), nullptr,
               GL_STATIC_DRAW);
  std::vector<Vertex> vertices;
  for (size_t first = 0; first < t.positions.size(); first += CHUNK) {
    vertices.resize(std::min(CHUNK, t.positions.size() - first));
    for (size_t i = 0; i < vertices.size(); ++i) {
      const size_t v = first + i;
      Vertex& o = vertices[i];
      std::memcpy(o.position, &t.positions[v].x, sizeof o.position);
      std::memcpy(o.normal, &t.normals[v].x, sizeof o.normal);
      o.object = t.object_id[v / 3];
      o.material = t.material_id[v / 3];
    }
    glBufferSubData(GL_ARRAY_BUFFER, static_cast<GLintptr>(first * sizeof(Vertex)),
                    static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)), vertices.data());
  }
  const auto offset = [](size_t bytes) { return reinterpret_cast<const void*>(bytes); };
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), offset(offsetof(Vertex, position)));
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), offset(offsetof(Vertex, normal)));
  glVertexAttribIPointer(2, 1, GL_UNSIGNED_INT, sizeof(Vertex), offset(offsetof(Vertex, object)));
  glVertexAttribIPointer(3, 1, GL_UNSIGNED_INT, sizeof(Vertex), offset(offsetof(Vertex, material)));
  for (GLuint a = 0; a < 4; ++a) glEnableVertexAttribArray(a);

  std::vector<MaterialGpu> materials;
  for (const Material& m : scene.materials) {
    materials.push_back({{float(m.color.r), float(m.color.g), float(m.color.b), float(m.ambient)},
                         {float(m.diffuse), float(m.specular), float(m.shininess), float(m.reflect)},
                         {float(m.transmit), float(m.ior), float(m.opacity), 0.f}});
  }
  if (materials.empty()) materials.push_back({});
  glGenBuffers(1, &materials_);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, materials_);
  glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(materials.size() * sizeof(MaterialGpu)),
               materials.data(), GL_STATIC_DRAW);
  glGenBuffers(1, &lights_);

  distance_program_ = std::make_unique<GlProgram>(std::vector<const char*>{"scene.vert"},
                                                  std::vector<const char*>{"cube_distance.frag"});
  phong_program_ = std::make_unique<GlProgram>(
      std::vector<const char*>{"scene.vert"},
      std::vector<const char*>{"common_scene.glsl", "common_shading.glsl", "phong.frag"});
  glFinish();
  check_gl("scene upload");
  timings_.upload_ms = ms_since(t0);
}

GlScene::~GlScene() {
  target_.reset();
  const GLuint textures[] = {shadow_maps_, environment_};
  glDeleteTextures(2, textures);
  glDeleteRenderbuffers(1, &lookup_depth_);
  glDeleteFramebuffers(1, &lookup_fbo_);
  glDeleteBuffers(1, &vbo_);
  glDeleteBuffers(1, &materials_);
  glDeleteBuffers(1, &lights_);
  glDeleteVertexArrays(1, &vao_);
}

GlScene::Target& GlScene::target(int width, int height, bool distance_pass) {
  if (width < 1 || height < 1 || width > max_size_ || height > max_size_) {
    throw RuntimeFailure("GL target " + std::to_string(width) + "x" + std::to_string(height) +
                         " exceeds GL_MAX_TEXTURE_SIZE " + std::to_string(max_size_));
  }
  if (!target_ || target_->width != width || target_->height != height ||
      target_->distance_pass != distance_pass) {
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
    lights.push_back({{float(p.x), float(p.y), float(p.z), layer},
                      {float(l.color.r), float(l.color.g), float(l.color.b), 0.f}});
  }
  if (lights.empty()) lights.push_back({});
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, lights_);
  glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(lights.size() * sizeof(LightGpu)),
               lights.data(), GL_DYNAMIC_DRAW);
}

void GlScene::draw(const GlProgram& program, const glm::mat4& clip, const glm::dvec3& center) {
  program.use();
  glUniformMatrix4fv(program.uniform("u_clip"), 1, GL_FALSE, &clip[0][0]);
  glUniform3f(program.uniform("u_center"), float(center.x), float(center.y), float(center.z));
  glUniform3f(program.uniform("u_ambient"), float(scene_.ambient.r), float(scene_.ambient.g),
              float(scene_.ambient.b));
  glUniform1i(program.uniform("u_light_count"), static_cast<GLint>(scene_.lights.size()));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, materials_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, lights_);
  glBindVertexArray(vao_);
  if (vertex_count_ > 0) glDrawArrays(GL_TRIANGLES, 0, vertex_count_);
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
  const bool environment = with_environment && environment_ != 0;
  glUniform1i(program.uniform("u_environment"), environment);
  glUniform1i(program.uniform("u_environment_map"), 2);
  glActiveTexture(GL_TEXTURE2);
  glBindTexture(GL_TEXTURE_CUBE_MAP, environment ? environment_ : 0);
  glActiveTexture(GL_TEXTURE0);
}

void GlScene::drop_environment() {
  glDeleteTextures(1, &environment_);
  environment_ = 0;
}

int GlScene::build_shadow_maps(int n) {
  shadow_layer_.assign(scene_.lights.size(), -1);
  int layers = 0;
  for (size_t i = 0; i < scene_.lights.size(); ++i) {
    if (scene_.lights[i].cast_shadows) shadow_layer_[i] = layers++;
  }
  if (layers == 0) return 0;
  // The lights are the scene's: maps built at this size by an earlier render are kept.
  if (shadow_maps_ != 0 && shadow_n_ == n) return layers;
  const Clock::time_point t0 = Clock::now();
  if (n > max_size_) throw RuntimeFailure("shadow map " + std::to_string(n) + " exceeds GL_MAX_TEXTURE_SIZE");
  shadow_n_ = n;
  glDeleteTextures(1, &shadow_maps_);
  glGenTextures(1, &shadow_maps_);
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, shadow_maps_);
  glTexStorage3D(GL_TEXTURE_CUBE_MAP_ARRAY, 1, GL_R32F, n, n, 6 * layers);
  glTexParameteri(GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  bind_lookup_target(n);
  const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_NONE};
  for (size_t i = 0; i < scene_.lights.size(); ++i) {
    if (shadow_layer_[i] < 0) continue;
    const glm::dvec3 light = scene_.lights[i].position;
    for (int face = 0; face < CUBE_FACES; ++face) {
      glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, shadow_maps_, 0, 6 * shadow_layer_[i] + face);
      glDrawBuffers(1, buffers);
      clear_lookup_target(n, true);
      draw(*distance_program_, face_clip_matrix(face, light, near_), light);
    }
  }
  glFinish();
  check_gl("cube shadow maps");
  timings_.shadow_maps_ms += ms_since(t0);
  return layers;
}

void GlScene::build_environment(const glm::dvec3& center, int n) {
  const Clock::time_point t0 = Clock::now();
  if (n > max_size_) throw RuntimeFailure("environment map " + std::to_string(n) + " exceeds GL_MAX_TEXTURE_SIZE");
  drop_environment();
  glGenTextures(1, &environment_);
  glBindTexture(GL_TEXTURE_CUBE_MAP, environment_);
  glTexStorage2D(GL_TEXTURE_CUBE_MAP, 1, GL_RGBA32F, n, n);
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
  bind_lookup_target(n);
  upload_lights(center);
  bind_lookups(*phong_program_, false);  // no environment inside the environment
  const GLenum buffers[] = {GL_COLOR_ATTACHMENT0};
  for (int face = 0; face < CUBE_FACES; ++face) {
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0,
                           GL_TEXTURE_CUBE_MAP_POSITIVE_X + static_cast<GLenum>(face), environment_, 0);
    glDrawBuffers(1, buffers);
    clear_lookup_target(n, false);
    draw(*phong_program_, face_clip_matrix(face, center, near_), center);
  }
  glFinish();
  check_gl("environment map");
  timings_.environment_ms += ms_since(t0);
}

// Binds the framebuffer that renders into the lookup textures, with an n x n depth buffer.
void GlScene::bind_lookup_target(int n) {
  if (!lookup_fbo_) glGenFramebuffers(1, &lookup_fbo_);
  glDeleteRenderbuffers(1, &lookup_depth_);
  glGenRenderbuffers(1, &lookup_depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, lookup_depth_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, n, n);
  glBindFramebuffer(GL_FRAMEBUFFER, lookup_fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, lookup_depth_);
}

// Clears the lookup framebuffer (shadow map: +infinity; environment: background).
void GlScene::clear_lookup_target(int n, bool distance) {
  glViewport(0, 0, n, n);
  set_pass_state();
  const float zero_depth = 0.f;
  glClearBufferfv(GL_DEPTH, 0, &zero_depth);
  const glm::dvec3& b = scene_.background;
  const float far[4] = {NO_DISTANCE, 0, 0, 0};
  const float bg[4] = {float(b.x), float(b.y), float(b.z), 1.f};
  glClearBufferfv(GL_COLOR, 0, distance ? far : bg);
}

void GlScene::cube_distance(const glm::dvec3& center, int n, CubeImage* distance, CubeIds* ids, int n_t) {
  const int h = n_t > 0 ? n_t : n;
  Target& t = target(n, h, true);
  *distance = CubeImage(n, 1);
  if (ids) ids->n = n;
  for (int face = 0; face < CUBE_FACES; ++face) {
    Clock::time_point t0 = Clock::now();
    t.clear(scene_.background);
    draw(*distance_program_, face_clip_matrix(face, center, near_), center);
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

CubeImage GlScene::cube_color(const glm::dvec3& center, int n) {
  Target& t = target(n, n, false);
  CubeImage out(n, 3);
  upload_lights(center);
  bind_lookups(*phong_program_, false);
  std::vector<float> rgba(static_cast<size_t>(n) * n * 4);
  for (int face = 0; face < CUBE_FACES; ++face) {
    Clock::time_point t0 = Clock::now();
    t.clear(scene_.background);
    draw(*phong_program_, face_clip_matrix(face, center, near_), center);
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

Image GlScene::camera_color(const Camera& camera) {
  Target& t = target(camera.width, camera.height, false);
  upload_lights(camera.position);
  bind_lookups(*phong_program_, true);
  Clock::time_point t0 = Clock::now();
  t.clear(scene_.background);
  const double aspect = static_cast<double>(camera.width) / camera.height;
  draw(*phong_program_,
       camera_clip_matrix(camera.position, camera.look_at, camera.up, glm::radians(camera.fov_y_deg),
                          aspect, near_),
       camera.position);
  glFinish();
  timings_.camera_ms += ms_since(t0);
  t0 = Clock::now();
  std::vector<float> rgba(static_cast<size_t>(camera.width) * camera.height * 4);
  t.read(0, GL_RGBA, GL_FLOAT, rgba.data());
  // GL's row 0 is the bottom; the image's row 0 is the top.
  Image out(camera.width, camera.height, 3);
  for (int y = 0; y < camera.height; ++y) {
    const float* src = &rgba[static_cast<size_t>(camera.height - 1 - y) * camera.width * 4];
    for (int x = 0; x < camera.width; ++x) out.set_rgb(x, y, {src[4 * x], src[4 * x + 1], src[4 * x + 2]});
  }
  timings_.readback_ms += ms_since(t0);
  check_gl("camera pass");
  return out;
}

}  // namespace abcube
