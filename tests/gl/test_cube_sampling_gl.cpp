// GL's own cube-map sampling is the ground truth of the face convention: faces rendered by
// the prepass and uploaded as GL_TEXTURE_CUBE_MAP faces (row j = texel row j) must give,
// when GL samples direction d, the texel cpu_core's direction_to_texel names for d.
#include <random>

#include <gtest/gtest.h>

#include "raster/cube_map.hpp"
#include "gl/gl_passes.hpp"
#include "gl_test_support.hpp"

namespace abcube {
namespace {

const char* SAMPLER = R"(#version 450 core
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Dirs { vec4 dirs[]; };
layout(std430, binding = 1) writeonly buffer Out { float values[]; };
uniform samplerCube u_cube;
uniform int u_count;
void main() {
  uint k = gl_GlobalInvocationID.x;
  if (k < uint(u_count)) values[k] = textureLod(u_cube, dirs[k].xyz, 0.0).r;
}
)";

GLuint compile_compute(const char* src) {
  const GLuint s = glCreateShader(GL_COMPUTE_SHADER);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  EXPECT_TRUE(ok);
  const GLuint p = glCreateProgram();
  glAttachShader(p, s);
  glLinkProgram(p);
  glDeleteShader(s);
  return p;
}

TEST(CubeConventionGl, GlCubeSamplingPicksCpuTexel) {
  test::test_context();
  const int n = 8;
  // One marker per texel centre, each its own object id (as in the texel test).
  SceneData s;
  for (int face = 0; face < CUBE_FACES; ++face) {
    const CubeFaceBasis& b = cube_face_basis(face);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const glm::dvec3 c = texel_center_direction(face, i, j, n);
        const double r = 0.8 / n;  // circumradius 0.4 texel
        test::add_triangle(s, c + r * b.s_axis, c - 0.5 * r * b.s_axis + 0.87 * r * b.t_axis,
                           c - 0.5 * r * b.s_axis - 0.87 * r * b.t_axis);
      }
    }
  }
  GlScene gl(s);
  CubeImage dist;
  CubeIds ids;
  gl.cube_distance(glm::dvec3(0), n, &dist, &ids);

  // Upload the ids (as floats, exact below 2^24) as the six faces of a cube texture.
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_CUBE_MAP, tex);
  for (int face = 0; face < CUBE_FACES; ++face) {
    std::vector<float> v(ids.faces[face].begin(), ids.faces[face].end());
    glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + static_cast<GLenum>(face), 0, GL_R32F, n, n, 0, GL_RED, GL_FLOAT,
                 v.data());
  }
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_NEAREST);

  // Random directions, kept away from texel borders so NEAREST has one answer.
  std::mt19937 rng(11);
  std::normal_distribution<double> g;
  std::vector<glm::vec4> dirs;
  while (dirs.size() < 4000) {
    const glm::dvec3 d(g(rng), g(rng), g(rng));
    const CubeCoord c = direction_to_cube(d);
    const double fs = c.s * n - std::floor(c.s * n), ft = c.t * n - std::floor(c.t * n);
    if (std::min({fs, 1 - fs, ft, 1 - ft}) < 0.05) continue;
    dirs.emplace_back(glm::vec3(d), 0.f);
  }
  GLuint buffers[2];
  glGenBuffers(2, buffers);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers[0]);
  glBufferData(GL_SHADER_STORAGE_BUFFER, GLsizeiptr(dirs.size() * sizeof(glm::vec4)), dirs.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers[1]);
  glBufferData(GL_SHADER_STORAGE_BUFFER, GLsizeiptr(dirs.size() * sizeof(float)), nullptr, GL_STATIC_READ);
  const GLuint prog = compile_compute(SAMPLER);
  glUseProgram(prog);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_CUBE_MAP, tex);
  glUniform1i(glGetUniformLocation(prog, "u_cube"), 0);
  glUniform1i(glGetUniformLocation(prog, "u_count"), GLint(dirs.size()));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buffers[0]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buffers[1]);
  glDispatchCompute(GLuint((dirs.size() + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<float> got(dirs.size());
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers[1]);
  glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, GLsizeiptr(got.size() * sizeof(float)), got.data());
  ASSERT_EQ(glGetError(), GLenum(GL_NO_ERROR));

  int wrong = 0;
  for (size_t k = 0; k < dirs.size(); ++k) {
    const CubeTexel t = direction_to_texel(glm::dvec3(dirs[k]), n);
    const float expected = float((t.face * n + t.j) * n + t.i);
    if (got[k] != expected && ++wrong <= 5) {
      ADD_FAILURE() << "direction (" << dirs[k].x << "," << dirs[k].y << "," << dirs[k].z << "): GL samples id "
                    << got[k] << ", CPU texel " << cube_face_name(t.face) << " (" << t.i << "," << t.j << ") id "
                    << expected;
    }
  }
  EXPECT_EQ(wrong, 0);
  glDeleteBuffers(2, buffers);
  glDeleteTextures(1, &tex);
  glDeleteProgram(prog);
}

}  // namespace
}  // namespace abcube
