#include "gl/gl_program.hpp"

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
         ABCUBE_GLSL_CONSTANT(PIXEL_WEIGHT_IMAGE) + ABCUBE_GLSL_CONSTANT(MASK_COLUMNS) +
         ABCUBE_GLSL_CONSTANT(MASK_ROWS) + ABCUBE_GLSL_CONSTANT(MASK_SAMPLES);
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

GLuint compile(GLenum stage, const std::vector<const char*>& files) {
  const std::string src = assemble(files);
  const GLuint s = glCreateShader(stage);
  const char* p = src.c_str();
  glShaderSource(s, 1, &p, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    std::string log(4096, '\0');
    GLsizei len = 0;
    glGetShaderInfoLog(s, static_cast<GLsizei>(log.size()), &len, log.data());
    log.resize(static_cast<size_t>(len));
    glDeleteShader(s);
    throw RuntimeFailure(std::string("GLSL compile failed (") + files.back() + "): " + log);
  }
  return s;
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
  id_ = glCreateProgram();
  glAttachShader(id_, vs);
  glAttachShader(id_, fs);
  glLinkProgram(id_);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (!ok) {
    std::string log(4096, '\0');
    GLsizei len = 0;
    glGetProgramInfoLog(id_, static_cast<GLsizei>(log.size()), &len, log.data());
    log.resize(static_cast<size_t>(len));
    glDeleteProgram(id_);
    throw RuntimeFailure("GLSL link failed: " + log);
  }
}

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
