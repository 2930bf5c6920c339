#include "gl/gl_cube_walks.hpp"

#include <glad/gl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
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

}  // namespace

void check_walk_ray(const WalkRay& r, size_t index) {
  const auto finite = [](const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  if (!finite(r.w) || !(std::fabs(glm::length(r.d) - 1.0) < 1e-6) || std::isnan(r.l_max) ||
      !std::isfinite(r.skip_radius)) {
    throw InputError("GPU cube walk: ray " + std::to_string(index) +
                     " has a non-finite origin, a direction not unit, a NaN end or a non-finite skipped radius");
  }
}

uint32_t walk_cap(int n, uint32_t max_texels) {
  if (n < 1) throw InputError("GPU cube walk: n must be >= 1, got " + std::to_string(n));
  const uint32_t cap = max_texels ? max_texels : CubeWalk::default_cap(n);
  if (cap > GPU_WALK_MAX_TEXELS) {
    throw InputError("GPU cube walk: a cap of " + std::to_string(cap) + " texels, above the GPU's " +
                     std::to_string(GPU_WALK_MAX_TEXELS) + "; lower n");
  }
  return cap;
}

void set_walk_uniforms(const GlProgram& p, int n, uint32_t cap) {
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
}

namespace {

// Both passes must have ended every walk of rays [first, end) of a chunk (flag 2) with the same
// count: a GL that stops a shader's loops early (llvmpipe past its iteration limit) fails
// here, not silently. `walked` and `filled` hold both passes' counts and flags (4 words a ray).
void check_batch(const std::vector<uint32_t>& walked, const std::vector<uint32_t>& filled, size_t first, size_t end,
                 size_t chunk) {
  for (size_t k = first; k < end; ++k) {
    const uint32_t count = walked[4 * k], flags = walked[4 * k + 1];
    if (!(flags & 2u) || filled[4 * k + 2] != count || filled[4 * k + 3] != flags) {
      throw RuntimeFailure("GPU cube walk: the GL ended ray " + std::to_string(chunk + k) +
                           "'s walk early (a loop limit?)");
    }
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

void GlCubeWalks::walk_batches(const std::vector<WalkRay>& rays, int n, uint32_t max_texels,
                               const std::function<void(const Batch&)>& visit, uint64_t batch_bytes) const {
  const uint32_t cap = walk_cap(n, max_texels);
  std::vector<GpuRay> packed(rays.size());
  for (size_t k = 0; k < rays.size(); ++k) {
    check_walk_ray(rays[k], k);
    packed[k] = {{rays[k].w.x, rays[k].w.y, rays[k].w.z, rays[k].l_max},
                 {rays[k].d.x, rays[k].d.y, rays[k].d.z, rays[k].skip_radius}};
  }
  const GlProgram& p = program_->program;
  const auto run = [&](bool fill, size_t first, size_t count) {
    set_walk_uniforms(p, n, cap);
    glUniform1i(p.uniform("fill"), fill ? 1 : 0);
    glUniform1ui(p.uniform("first_ray"), static_cast<GLuint>(first));
    glUniform1ui(p.uniform("ray_count"), static_cast<GLuint>(count));
    dispatch(p, (count + 63) / 64);
    check_gl("GPU cube walk");
  };
  // The rays go in chunks (their storage blocks well under the 128 MiB a GL must offer); in
  // each, the count pass, then the fill pass in batches of rays whose texels take at most
  // batch_bytes (one ray's at least).
  for (size_t chunk = 0; chunk < rays.size(); chunk += WALK_RAY_CHUNK) {
    const size_t chunk_rays = std::min(WALK_RAY_CHUNK, rays.size() - chunk);
    const GlBuffer ray_buffer(chunk_rays * sizeof(GpuRay), packed.data() + chunk);
    const GlBuffer counts(chunk_rays * 4 * sizeof(uint32_t), nullptr);
    const auto bind = [&] {
      ray_buffer.bind(CUBE_WALK_RAYS_BINDING);
      counts.bind(CUBE_WALK_COUNTS_BINDING);
    };
    bind();
    counts.bind(CUBE_WALK_TEXELS_BINDING);  // not touched by the count pass, but bound
    counts.bind(CUBE_WALK_OFFSETS_BINDING);
    run(false, 0, chunk_rays);
    const std::vector<uint32_t> walked = counts.read<uint32_t>(4 * chunk_rays);
    for (size_t first = 0; first < chunk_rays;) {
      Batch batch;
      batch.chunk = chunk;
      batch.first = first;
      size_t end = first;
      while (end < chunk_rays &&
             (end == first || (batch.texel_count + walked[4 * end]) * sizeof(GpuTexel) <= batch_bytes)) {
        batch.offsets.push_back(static_cast<uint32_t>(batch.texel_count));
        batch.texel_count += walked[4 * end];
        ++end;
      }
      batch.end = end;
      const GlBuffer offset_buffer(batch.offsets.size() * sizeof(uint32_t), batch.offsets.data());
      const GlBuffer texels(batch.texel_count * sizeof(GpuTexel), nullptr);
      bind();  // a visit may have bound others
      offset_buffer.bind(CUBE_WALK_OFFSETS_BINDING);
      texels.bind(CUBE_WALK_TEXELS_BINDING);
      run(true, first, end - first);
      const std::vector<uint32_t> filled = counts.read<uint32_t>(4 * end);
      check_batch(walked, filled, first, end, chunk);
      batch.counts = &walked;
      batch.texels = &texels;
      batch.offset_buffer = &offset_buffer;
      visit(batch);
      first = end;
    }
  }
}

std::vector<RayWalk> GlCubeWalks::walk(const std::vector<WalkRay>& rays, int n, uint32_t max_texels) const {
  std::vector<RayWalk> out(rays.size());
  walk_batches(rays, n, max_texels, [&](const Batch& b) {
    const std::vector<GpuTexel> all = b.texels->read<GpuTexel>(b.texel_count);
    for (size_t k = b.first; k < b.end; ++k) {
      RayWalk& w = out[b.chunk + k];
      const uint32_t count = (*b.counts)[4 * k];
      w.aborted = ((*b.counts)[4 * k + 1] & 1u) != 0;
      const GpuTexel* g = all.data() + b.offsets[k - b.first];
      for (uint32_t t = 0; t < count; ++t, ++g) {
        WalkTexel texel;
        texel.face = g->face, texel.i = g->i, texel.j = g->j, texel.l0 = g->l0, texel.l1 = g->l1;
        texel.after_gap = g->after_gap != 0;
        w.texels.push_back(texel);
      }
    }
  });
  return out;
}

void for_spread_triangles(const TriangleSoup& soup, size_t max_triangles,
                          const std::function<void(size_t, const glm::dvec3&, const glm::dvec3&)>& visit) {
  const size_t count = soup.triangle_count();
  const size_t stride = std::max<size_t>(1, (count + max_triangles - 1) / std::max<size_t>(1, max_triangles));
  for (size_t t = 0; t < count; t += stride) {
    const glm::dvec3 a(soup.positions[3 * t]), b(soup.positions[3 * t + 1]), c(soup.positions[3 * t + 2]);
    const glm::dvec3 normal = glm::cross(b - a, c - a);
    const double n_len = glm::length(normal);
    if (n_len > 0.0 && std::isfinite(n_len)) visit(t, (a + b + c) / 3.0, normal / n_len);
  }
}

std::vector<WalkRay> scene_walk_rays(const SceneData& scene, const glm::dvec3& centre, size_t max_triangles) {
  std::vector<WalkRay> rays;
  for_spread_triangles(*scene.triangles, max_triangles, [&](size_t, const glm::dvec3& x, const glm::dvec3& normal) {
    const glm::dvec3 w = x - centre;
    const double w_len = glm::length(w);
    if (!(w_len > 0.0) || !std::isfinite(w_len)) return;
    rays.push_back({w, glm::reflect(w / w_len, normal), std::numeric_limits<double>::infinity(), 0.0});
    for (const PointLight& light : scene.lights) {
      const glm::dvec3 to_light = light.position - centre - w;
      const double l = glm::length(to_light);
      if (l > 0.0 && std::isfinite(l)) rays.push_back({w, to_light / l, l, 0.0});
    }
  });
  return rays;
}

std::vector<RayWalk> cpu_cube_walks(const std::vector<WalkRay>& rays, int n, uint32_t max_texels) {
  std::vector<RayWalk> out(rays.size());
  for (size_t k = 0; k < rays.size(); ++k) {
    check_walk_ray(rays[k], k);
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
  for (size_t r = 0; r < a.size(); ++r) {
    c.texels += a[r].texels.size();
    const std::vector<WalkTexel>& x = a[r].texels;
    const std::vector<WalkTexel>& y = r < b.size() ? b[r].texels : x;
    const bool walks_alike = r < b.size() && a[r].aborted == b[r].aborted && x.size() == y.size();
    // The first texel that differs in its place or bits, and whether every one is at the
    // same place with both ends within rounding.
    size_t k = 0;
    bool rounding = walks_alike;
    for (size_t t = 0; walks_alike && t < x.size(); ++t) {
      const WalkTexel &p = x[t], &q = y[t];
      const bool place = p.face == q.face && p.i == q.i && p.j == q.j && p.after_gap == q.after_gap;
      const bool bits = place && same_bits(p.l0, q.l0) && same_bits(p.l1, q.l1);
      if (bits && k == t) ++k;
      rounding = rounding && place && within_rounding(p.l0, q.l0) && within_rounding(p.l1, q.l1);
    }
    if (walks_alike && k == x.size()) {
      ++c.identical;
      continue;
    }
    std::ostringstream what;
    if (!count_not_identical(r, rounding, r < b.size(), &c, &what)) continue;
    what << x.size() << " texels" << (a[r].aborted ? " (aborted)" : "") << " against " << y.size()
         << (b[r].aborted ? " (aborted)" : "");
    if (k < x.size() && k < y.size()) {
      const WalkTexel &p = x[k], &q = y[k];
      what << "; texel " << k << ": face " << p.face << " (" << p.i << ", " << p.j << ") l [" << p.l0 << ", " << p.l1
           << "] against face " << q.face << " (" << q.i << ", " << q.j << ") l [" << q.l0 << ", " << q.l1 << "]";
    }
    c.example = what.str();
  }
  count_extra_rays(a.size(), b.size(), &c);
  return c;
}

}  // namespace abcube
