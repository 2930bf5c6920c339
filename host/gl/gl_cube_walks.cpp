#include "gl/gl_cube_walks.hpp"

#include <glad/gl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>

#include "base/error.hpp"
#include "gl/gl_compute.hpp"
#include "gl/gl_program.hpp"
#include "gl/glsl_shared.hpp"
#include "raster/cube_map.hpp"

namespace abcube {

namespace {

// shaders/cube_walks.comp's WalkRay and WalkTexelOut in std430.
struct GpuRay {
  double w_lmax[4];
  double d_skip[4];
};
struct GpuTexel {
  int32_t face, i, j, after_gap;
  double l0, l1;
};
static_assert(sizeof(GpuRay) == 64 && sizeof(GpuTexel) == 32, "must match shaders/cube_walks.comp");

void check_ray(const WalkRay& r, size_t index) {
  const auto finite = [](const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  if (!finite(r.w) || !(std::fabs(glm::length(r.d) - 1.0) < 1e-6)) {
    throw InputError("GPU cube walk: ray " + std::to_string(index) +
                     " has a non-finite origin or a direction not unit");
  }
}

}  // namespace

struct GlCubeWalks::Program {
  GlProgram program{std::vector<const char*>{"double_math.glsl", "cube_walk.glsl", "cube_walks.comp"}};
};

GlCubeWalks::GlCubeWalks() {
  require_storage_bindings("GPU cube walk", CUBE_WALK_OFFSETS_BINDING);
  program_ = std::make_unique<Program>();
}
GlCubeWalks::~GlCubeWalks() = default;

std::vector<RayWalk> GlCubeWalks::walk(const std::vector<WalkRay>& rays, int n, uint32_t max_texels) const {
  if (n < 1) throw InputError("GPU cube walk: n must be >= 1, got " + std::to_string(n));
  const uint32_t cap = max_texels ? max_texels : CubeWalk::default_cap(n);
  if (cap > GPU_WALK_MAX_TEXELS) {
    throw InputError("GPU cube walk: a cap of " + std::to_string(cap) + " texels, above the GPU's " +
                     std::to_string(GPU_WALK_MAX_TEXELS) + "; lower n");
  }
  std::vector<GpuRay> packed(rays.size());
  for (size_t k = 0; k < rays.size(); ++k) {
    check_ray(rays[k], k);
    packed[k] = {{rays[k].w.x, rays[k].w.y, rays[k].w.z, rays[k].l_max},
                 {rays[k].d.x, rays[k].d.y, rays[k].d.z, rays[k].skip_radius}};
  }
  std::vector<RayWalk> out(rays.size());
  if (rays.empty()) return out;
  const GlProgram& p = program_->program;
  p.use();
  for (int f = 0; f < CUBE_FACES; ++f) {
    const CubeFaceBasis& b = cube_face_basis(f);
    const std::string at = "[" + std::to_string(f) + "]";
    glUniform3d(p.uniform(("face_forward" + at).c_str()), b.forward.x, b.forward.y, b.forward.z);
    glUniform3d(p.uniform(("face_s_axis" + at).c_str()), b.s_axis.x, b.s_axis.y, b.s_axis.z);
    glUniform3d(p.uniform(("face_t_axis" + at).c_str()), b.t_axis.x, b.t_axis.y, b.t_axis.z);
  }
  glUniform1d(p.uniform("centre_pass_rel"), CENTRE_PASS_REL);
  glUniform1i(p.uniform("face_resolution"), n);
  glUniform1ui(p.uniform("walk_cap_texels"), cap);
  const GlBuffer ray_buffer(packed.size() * sizeof(GpuRay), packed.data());
  ray_buffer.bind(CUBE_WALK_RAYS_BINDING);
  const auto run = [&](bool fill, size_t first, size_t count) {
    p.use();
    glUniform1i(p.uniform("fill"), fill ? 1 : 0);
    glUniform1ui(p.uniform("first_ray"), static_cast<GLuint>(first));
    glUniform1ui(p.uniform("ray_count"), static_cast<GLuint>(count));
    dispatch(p, (count + 63) / 64);
    check_gl("GPU cube walk");
  };
  // The count pass: every ray's texels and cap.
  const GlBuffer counts(rays.size() * 2 * sizeof(uint32_t), nullptr);
  counts.bind(CUBE_WALK_COUNTS_BINDING);
  counts.bind(CUBE_WALK_TEXELS_BINDING);  // not touched by the count pass, but bound
  counts.bind(CUBE_WALK_OFFSETS_BINDING);
  run(false, 0, rays.size());
  const std::vector<uint32_t> walked = counts.read<uint32_t>(2 * rays.size());
  // The fill pass, in batches of rays whose texels take at most WALK_BATCH_BYTES (one ray's
  // at least).
  constexpr uint64_t WALK_BATCH_BYTES = uint64_t{64} << 20;
  for (size_t first = 0; first < rays.size();) {
    std::vector<uint32_t> offsets;
    uint64_t texel_count = 0;
    size_t end = first;
    while (end < rays.size() &&
           (end == first || (texel_count + walked[2 * end]) * sizeof(GpuTexel) <= WALK_BATCH_BYTES)) {
      offsets.push_back(static_cast<uint32_t>(texel_count));
      texel_count += walked[2 * end];
      ++end;
    }
    const GlBuffer offset_buffer(offsets.size() * sizeof(uint32_t), offsets.data());
    const GlBuffer texels(texel_count * sizeof(GpuTexel), nullptr);
    offset_buffer.bind(CUBE_WALK_OFFSETS_BINDING);
    texels.bind(CUBE_WALK_TEXELS_BINDING);
    run(true, first, end - first);
    const std::vector<GpuTexel> all = texels.read<GpuTexel>(texel_count);
    for (size_t k = first; k < end; ++k) {
      RayWalk& w = out[k];
      w.aborted = walked[2 * k + 1] != 0;
      const GpuTexel* g = all.data() + offsets[k - first];
      for (uint32_t t = 0; t < walked[2 * k]; ++t, ++g) {
        WalkTexel texel;
        texel.face = g->face, texel.i = g->i, texel.j = g->j, texel.l0 = g->l0, texel.l1 = g->l1;
        texel.after_gap = g->after_gap != 0;
        w.texels.push_back(texel);
      }
    }
    first = end;
  }
  return out;
}

std::vector<WalkRay> scene_walk_rays(const SceneData& scene, const glm::dvec3& centre, size_t max_triangles) {
  const TriangleSoup& soup = *scene.triangles;
  const size_t count = soup.triangle_count();
  const size_t stride = std::max<size_t>(1, (count + max_triangles - 1) / std::max<size_t>(1, max_triangles));
  std::vector<WalkRay> rays;
  for (size_t t = 0; t < count; t += stride) {
    const glm::dvec3 a(soup.positions[3 * t]), b(soup.positions[3 * t + 1]), c(soup.positions[3 * t + 2]);
    const glm::dvec3 w = (a + b + c) / 3.0 - centre;
    const glm::dvec3 normal = glm::cross(b - a, c - a);
    const double w_len = glm::length(w), n_len = glm::length(normal);
    if (!(w_len > 0.0) || !(n_len > 0.0) || !std::isfinite(w_len)) continue;
    rays.push_back({w, glm::reflect(w / w_len, normal / n_len), std::numeric_limits<double>::infinity(), 0.0});
    for (const PointLight& light : scene.lights) {
      const glm::dvec3 to_light = light.position - centre - w;
      const double l = glm::length(to_light);
      if (l > 0.0 && std::isfinite(l)) rays.push_back({w, to_light / l, l, 0.0});
    }
  }
  return rays;
}

std::vector<RayWalk> cpu_cube_walks(const std::vector<WalkRay>& rays, int n, uint32_t max_texels) {
  std::vector<RayWalk> out(rays.size());
  for (size_t k = 0; k < rays.size(); ++k) {
    check_ray(rays[k], k);
    CubeWalk walk(rays[k].w, rays[k].d, n, rays[k].l_max, rays[k].skip_radius, max_texels);
    WalkTexel t;
    while (walk.next(&t)) out[k].texels.push_back(t);
    out[k].aborted = walk.aborted();
  }
  return out;
}

WalkComparison compare_walks(const std::vector<RayWalk>& a, const std::vector<RayWalk>& b) {
  WalkComparison c;
  c.rays = a.size();
  const auto differ = [&](size_t r, const std::string& what) {
    if (c.first_differing < 0) {
      c.first_differing = static_cast<long>(r);
      c.example = "ray " + std::to_string(r) + ": " + what;
    }
  };
  for (size_t r = 0; r < a.size(); ++r) {
    c.texels += a[r].texels.size();
    if (r >= b.size()) {
      differ(r, "missing from the second set");
      continue;
    }
    const std::vector<WalkTexel>& x = a[r].texels;
    const std::vector<WalkTexel>& y = b[r].texels;
    const auto same_texel = [](const WalkTexel& p, const WalkTexel& q) {
      return p.face == q.face && p.i == q.i && p.j == q.j && p.after_gap == q.after_gap && p.l0 == q.l0 && p.l1 == q.l1;
    };
    size_t k = 0;
    while (k < x.size() && k < y.size() && same_texel(x[k], y[k])) ++k;
    if (k == x.size() && k == y.size() && a[r].aborted == b[r].aborted) {
      ++c.identical;
      continue;
    }
    std::ostringstream what;
    what.precision(17);
    what << x.size() << " texels" << (a[r].aborted ? " (aborted)" : "") << " against " << y.size()
         << (b[r].aborted ? " (aborted)" : "");
    if (k < x.size() && k < y.size()) {
      const WalkTexel &p = x[k], &q = y[k];
      what << "; texel " << k << ": face " << p.face << " (" << p.i << ", " << p.j << ") l [" << p.l0 << ", " << p.l1
           << "] against face " << q.face << " (" << q.i << ", " << q.j << ") l [" << q.l0 << ", " << q.l1 << "]";
    }
    differ(r, what.str());
  }
  return c;
}

}  // namespace abcube
