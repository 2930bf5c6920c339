// GLSL programs built from the embedded shaders/ files.
#pragma once
#include <glad/gl.h>

#include <string>
#include <vector>

namespace abcube {

// A linked program. Each stage is "#version 450 core" followed by the named files in order
// (shared common_*.glsl first). Throws RuntimeFailure with the compiler's log on error.
class GlProgram {
 public:
  GlProgram(const std::vector<const char*>& vertex_files, const std::vector<const char*>& fragment_files);
  // A compute program of one stage.
  explicit GlProgram(const std::vector<const char*>& compute_files);
  ~GlProgram();
  GlProgram(const GlProgram&) = delete;
  GlProgram& operator=(const GlProgram&) = delete;

  void use() const { glUseProgram(id_); }
  GLint uniform(const char* name) const { return glGetUniformLocation(id_, name); }

 private:
  GLuint id_ = 0;
};

// Throws RuntimeFailure naming `what` if GL has recorded an error.
void check_gl(const char* what);

}  // namespace abcube
