// What the GL compute passes share (the GPU A-buffer, the GPU cube walks): a storage buffer
// and a dispatch of any number of workgroups. The GL context must be current.
#pragma once
#include <glad/gl.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "base/error.hpp"
#include "gl/gl_program.hpp"

namespace abcube {

// A storage buffer, deleted with its owner.
class GlBuffer {
 public:
  GlBuffer(uint64_t bytes, const void* data) {
    glCreateBuffers(1, &id_);
    glNamedBufferData(id_, static_cast<GLsizeiptr>(std::max<uint64_t>(bytes, 4)), data, GL_DYNAMIC_COPY);
    check_gl("GL compute: a storage buffer");
  }
  ~GlBuffer() { glDeleteBuffers(1, &id_); }
  GlBuffer(const GlBuffer&) = delete;
  GlBuffer& operator=(const GlBuffer&) = delete;

  GLuint id() const { return id_; }
  void bind(unsigned binding) const { glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, id_); }
  void zero() const { glClearNamedBufferData(id_, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr); }
  void fill(uint32_t word) const { glClearNamedBufferData(id_, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &word); }
  template <class T>
  std::vector<T> read(size_t count) const {
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<T> out(count);
    if (count > 0) glGetNamedBufferSubData(id_, 0, static_cast<GLsizeiptr>(count * sizeof(T)), out.data());
    check_gl("GL compute: reading a buffer back");
    return out;
  }

 private:
  GLuint id_ = 0;
};

// Runs `groups` workgroups of the current program `p`, in rows of at most 65535 (the
// dispatch's guaranteed width), each program reading its index as
// gl_WorkGroupID.y * groups_per_row + gl_WorkGroupID.x.
inline void dispatch(const GlProgram& p, uint64_t groups) {
  if (groups == 0) return;
  const uint64_t row = std::min<uint64_t>(groups, 65535), rows = (groups + row - 1) / row;
  if (rows > 65535) throw RuntimeFailure("GL compute: " + std::to_string(groups) + " workgroups in one dispatch");
  glUniform1ui(p.uniform("groups_per_row"), static_cast<GLuint>(row));
  glDispatchCompute(static_cast<GLuint>(row), static_cast<GLuint>(rows), 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

// Throws RuntimeFailure naming `what` unless the GL offers storage buffer binding `highest`.
inline void require_storage_bindings(const char* what, unsigned highest) {
  GLint bindings = 0;
  glGetIntegerv(GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS, &bindings);
  if (bindings <= static_cast<GLint>(highest)) {
    throw RuntimeFailure(std::string(what) + ": the GL offers " + std::to_string(bindings) +
                         " storage buffer bindings, " + std::to_string(highest + 1) + " needed");
  }
}

// The most bytes one storage block may take (128 MiB at least on any GL 4.3).
inline uint64_t max_block_bytes() {
  GLint64 block = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block);
  return static_cast<uint64_t>(block);
}

// Throws RuntimeFailure unless `bytes` of `what` fit one storage block; `advice` ends the line.
inline void require_block_bytes(const std::string& what, uint64_t bytes, const std::string& advice) {
  if (bytes > max_block_bytes()) {
    throw RuntimeFailure(what + " take " + std::to_string(bytes) +
                         " bytes, above the GL's GL_MAX_SHADER_STORAGE_BLOCK_SIZE " +
                         std::to_string(max_block_bytes()) + "; " + advice);
  }
}

// Throws RuntimeFailure naming `what` unless one compute shader may use `count` storage blocks.
inline void require_compute_blocks(const char* what, int count) {
  GLint blocks = 0;
  glGetIntegerv(GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS, &blocks);
  if (blocks < count) {
    throw RuntimeFailure(std::string(what) + ": the GL offers a compute shader " + std::to_string(blocks) +
                         " storage blocks, " + std::to_string(count) + " needed");
  }
}

}  // namespace abcube
