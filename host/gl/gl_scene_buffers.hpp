// The scene uploaded to the GL (GlSceneBuffers): the soup's vertex arrays, each triangle's
// ids, the materials, the lights and the base-colour textures, and the draw calls every pass
// makes through them. Needs a current GL context for its whole life.
#pragma once
#include <glad/gl.h>

#include <vector>

#include <glm/glm.hpp>

#include "gl/gl_types.hpp"
#include "gl/gl_program.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

struct MirrorView;

class GlSceneBuffers {
 public:
  GlSceneBuffers(const SceneData& scene, const GlSceneOptions& options);
  ~GlSceneBuffers();
  GlSceneBuffers(const GlSceneBuffers&) = delete;
  GlSceneBuffers& operator=(const GlSceneBuffers&) = delete;

  const SceneData& scene() const { return scene_; }

  // scene.vert and what goes before it: `before`, then triangle_ids.glsl where it is used.
  std::vector<const char*> vertex_stage(const char* before = nullptr) const;

  // The view's uniforms (clip, eye, clip plane, the mirror left out, the tie rule when
  // `ties`) and the scene's storage buffers set on `program`, made current. The shadow
  // passes draw without the tie rule: their casters all count, and their translucent peels
  // order equal depths by triangle (shadow_caster.frag).
  void set_view(const GlProgram& program, const glm::mat4& clip, const MirrorView& view, bool ties = true) const;
  // Every triangle of the scene drawn through `view` (set_view first).
  void draw_scene(const GlProgram& program, const glm::mat4& clip, const MirrorView& view, bool ties = true) const;
  // The same from `center`, level 0.
  void draw(const GlProgram& program, const glm::mat4& clip, const glm::dvec3& center, bool ties = true) const;
  void bind_vertex_array() const { glBindVertexArray(vao_); }

  // The lights relative to `center` in their storage buffer, each with its shadow map's
  // layer and its shadow-volume counts (per light; -1, or a light past the vector's end:
  // none).
  void upload_lights(const glm::dvec3& center, const std::vector<int>& shadow_layer, const std::vector<int>& volume_bit,
                     const std::vector<int>& translucent_bit) const;
  // The base-colour texture arrays on their units (gl_targets.hpp TEXTURE_UNIT), and
  // whether they are sampled at level 0 alone.
  void bind_textures(const GlProgram& program, bool level0) const;

  // The arrays the per-pixel shading reads as storage buffers (camera_groups.frag).
  GLuint positions() const { return positions_; }
  GLuint normals() const { return normals_; }
  GLuint material_ids() const { return material_ids_; }
  GLuint uvs() const { return uv_vbo_; }  // 0 when the scene has no texture coordinates
  GLsizei vertex_count() const { return vertex_count_; }

  bool pinned() const { return pinned_; }
  bool triangle_ids() const { return triangle_ids_; }
  int max_size() const { return max_size_; }  // GL_MAX_TEXTURE_SIZE
  double near_distance() const { return near_; }

 private:
  // A GL buffer holding `bytes` at `data`: that memory itself when pin_soup_ and the GL
  // can (the soup must then outlive the buffer), else a copy.
  GLuint soup_buffer(const void* data, size_t bytes);
  void upload_vertex_ids();
  void upload_materials();
  // Per material: -1, or its texture's array + MAX_TEXTURE_ARRAYS * layer.
  std::vector<float> upload_textures();

  const SceneData& scene_;
  // The scene's arrays: positions, normals, texture coordinates, each triangle's object and
  // material are the soup's (soup_buffer); vertex_ids_ each vertex's ids, where the vertex
  // stage reads no storage buffer of triangle ids (triangle_ids_ false).
  GLuint vao_ = 0, positions_ = 0, normals_ = 0, object_ids_ = 0, material_ids_ = 0, vertex_ids_ = 0;
  GLuint uv_vbo_ = 0, materials_ = 0, lights_ = 0;
  std::vector<GLuint> texture_arrays_;  // by size class; the material's code names array and layer
  GLsizei vertex_count_ = 0;
  bool triangle_ids_ = false;
  bool pin_soup_ = true;
  bool pinned_ = false;  // every soup buffer is the soup's memory
  int max_size_ = 0;
  double near_ = 1e-4;
};

}  // namespace abcube
