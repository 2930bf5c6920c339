#include "gl/gl_program.hpp"

#include <initializer_list>
#include <sstream>

#include "base/error.hpp"
#include "gl/glsl_shared.hpp"
#include "gl/shader_sources.hpp"

namespace abcube {

// One #define a constant, named as in C++ (the macro keeps the name and the value one text).
#define ABCUBE_GLSL_CONSTANT(name) "#define " #name " " + std::to_string(name) + "\n"

std::string glsl_prelude() {
  return std::string("// ---- glsl_shared.hpp\n") + ABCUBE_GLSL_CONSTANT(MAX_SHADOW_PEELS) +
         ABCUBE_GLSL_CONSTANT(MAX_TEXTURE_ARRAYS) + ABCUBE_GLSL_CONSTANT(MATERIALS_BINDING) +
         ABCUBE_GLSL_CONSTANT(LIGHTS_BINDING) + ABCUBE_GLSL_CONSTANT(RECURSED_BINDING) +
         ABCUBE_GLSL_CONSTANT(POSITIONS_BINDING) + ABCUBE_GLSL_CONSTANT(UVS_BINDING) +
         ABCUBE_GLSL_CONSTANT(PORTALS_BINDING) + ABCUBE_GLSL_CONSTANT(NORMALS_BINDING) +
         ABCUBE_GLSL_CONSTANT(TRIANGLE_MATERIALS_BINDING) + ABCUBE_GLSL_CONSTANT(VOLUME_CAPS_BINDING) +
         ABCUBE_GLSL_CONSTANT(OBJECT_IDS_BINDING) + ABCUBE_GLSL_CONSTANT(MATERIAL_IDS_BINDING) +
         ABCUBE_GLSL_CONSTANT(TARGET_IMAGE) + ABCUBE_GLSL_CONSTANT(PIXEL_COLOR_IMAGE) +
         ABCUBE_GLSL_CONSTANT(PIXEL_WEIGHT_IMAGE) + ABCUBE_GLSL_CONSTANT(ABUFFER_SETUPS_BINDING) +
         ABCUBE_GLSL_CONSTANT(ABUFFER_VIEWS_BINDING) + ABCUBE_GLSL_CONSTANT(ABUFFER_OFFSETS_BINDING) +
         ABCUBE_GLSL_CONSTANT(ABUFFER_CURSORS_BINDING) + ABCUBE_GLSL_CONSTANT(ABUFFER_FRAGMENTS_BINDING) +
         ABCUBE_GLSL_CONSTANT(ABUFFER_TRIANGLES_BINDING) + ABCUBE_GLSL_CONSTANT(ABUFFER_STATS_BINDING) +
         ABCUBE_GLSL_CONSTANT(ABUFFER_SCAN_VALUES_BINDING) + ABCUBE_GLSL_CONSTANT(ABUFFER_SCAN_SUMS_BINDING) +
         ABCUBE_GLSL_CONSTANT(ABUFFER_ITEMS_BINDING) + ABCUBE_GLSL_CONSTANT(ABUFFER_TILE) +
         ABCUBE_GLSL_CONSTANT(ABUFFER_GPU_LIST_MAX) + ABCUBE_GLSL_CONSTANT(ABUFFER_SCAN_BLOCK) +
         ABCUBE_GLSL_CONSTANT(CUBE_WALK_RAYS_BINDING) + ABCUBE_GLSL_CONSTANT(CUBE_WALK_TEXELS_BINDING) +
         ABCUBE_GLSL_CONSTANT(CUBE_WALK_COUNTS_BINDING) + ABCUBE_GLSL_CONSTANT(CUBE_WALK_OFFSETS_BINDING) +
         ABCUBE_GLSL_CONSTANT(CUBE_SCAN_RAYS_BINDING) + ABCUBE_GLSL_CONSTANT(CUBE_SCAN_LISTS_BINDING) +
         ABCUBE_GLSL_CONSTANT(CUBE_SCAN_FRAGMENTS_BINDING) + ABCUBE_GLSL_CONSTANT(CUBE_SCAN_PLANES_BINDING) +
         ABCUBE_GLSL_CONSTANT(CUBE_SCAN_OBJECTS_BINDING) + ABCUBE_GLSL_CONSTANT(CUBE_SCAN_CANDIDATES_BINDING) +
         ABCUBE_GLSL_CONSTANT(CUBE_SCAN_POSITIONS_BINDING) + ABCUBE_GLSL_CONSTANT(CUBE_REFINE_NEIGHBOURS_BINDING) +
         ABCUBE_GLSL_CONSTANT(GPU_REFINE_MAX_STEPS) + ABCUBE_GLSL_CONSTANT(GPU_REFINE_MAX_TRIANGLES) +
         ABCUBE_GLSL_CONSTANT(GPU_CROSSING_WINDOW_TEXELS) + ABCUBE_GLSL_CONSTANT(CUBE_SCAN_BLOCKS_BINDING) +
         ABCUBE_GLSL_CONSTANT(GPU_BOUNDS_BLOCK) + ABCUBE_GLSL_CONSTANT(RESOLVE_VIEW_BINDING) +
         ABCUBE_GLSL_CONSTANT(RESOLVE_LISTS_BINDING) + ABCUBE_GLSL_CONSTANT(RESOLVE_FRAGMENTS_BINDING) +
         ABCUBE_GLSL_CONSTANT(RESOLVE_TRIANGLES_BINDING) + ABCUBE_GLSL_CONSTANT(RESOLVE_POSITIONS_BINDING) +
         ABCUBE_GLSL_CONSTANT(RESOLVE_COUNTS_BINDING) + ABCUBE_GLSL_CONSTANT(RESOLVE_STARTS_BINDING) +
         ABCUBE_GLSL_CONSTANT(RESOLVE_STEPS_BINDING) + ABCUBE_GLSL_CONSTANT(RESOLVE_STACK) +
         ABCUBE_GLSL_CONSTANT(MASK_COLUMNS) + ABCUBE_GLSL_CONSTANT(MASK_ROWS) + ABCUBE_GLSL_CONSTANT(MASK_SAMPLES);
}

#undef ABCUBE_GLSL_CONSTANT

namespace {

std::string assemble(const std::vector<const char*>& files) {
  std::string src = "#version 450 core\n" + glsl_prelude();
  for (const char* f : files) {
    const char* text = embedded_shader(f);
    if (text == nullptr) throw RuntimeFailure(std::string("shader not embedded in this build: ") + f);
    src += "// ---- " + std::string(f) + "\n" + text + "\n";
  }
  return src;
}

// A shader's or a program's info log (`get` is glGetShaderInfoLog or glGetProgramInfoLog).
std::string info_log(GLuint id, void (*get)(GLuint, GLsizei, GLsizei*, GLchar*)) {
  std::string log(4096, '\0');
  GLsizei len = 0;
  get(id, static_cast<GLsizei>(log.size()), &len, log.data());
  log.resize(static_cast<size_t>(len));
  return log;
}

GLuint compile(GLenum stage, const std::vector<const char*>& files) {
  const std::string src = assemble(files);
  const GLuint s = glCreateShader(stage);
  const char* p = src.c_str();
  glShaderSource(s, 1, &p, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    const std::string log = info_log(s, glGetShaderInfoLog);
    glDeleteShader(s);
    throw RuntimeFailure(std::string("GLSL compile failed (") + files.back() + "): " + log);
  }
  return s;
}

// A program of the compiled `stages`, which it deletes, linked or not.
GLuint link(std::initializer_list<GLuint> stages) {
  const GLuint id = glCreateProgram();
  for (GLuint s : stages) glAttachShader(id, s);
  glLinkProgram(id);
  for (GLuint s : stages) glDeleteShader(s);
  GLint ok = 0;
  glGetProgramiv(id, GL_LINK_STATUS, &ok);
  if (!ok) {
    const std::string log = info_log(id, glGetProgramInfoLog);
    glDeleteProgram(id);
    throw RuntimeFailure("GLSL link failed: " + log);
  }
  return id;
}

}  // namespace

GlProgram::GlProgram(const std::vector<const char*>& vertex_files, const std::vector<const char*>& fragment_files) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex_files);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment_files);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  id_ = link({vs, fs});
}

GlProgram::GlProgram(const std::vector<const char*>& compute_files)
    : id_(link({compile(GL_COMPUTE_SHADER, compute_files)})) {}

GlProgram::~GlProgram() { glDeleteProgram(id_); }

void check_gl(const char* what) {
  const GLenum e = glGetError();
  if (e != GL_NO_ERROR) {
    std::ostringstream s;
    s << "OpenGL error 0x" << std::hex << e << " in " << what;
    throw RuntimeFailure(s.str());
  }
}

}  // namespace abcube
