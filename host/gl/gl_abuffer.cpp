#include "gl/gl_abuffer.hpp"

#include <glad/gl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "gl/gl_program.hpp"
#include "gl/glsl_shared.hpp"
#include "raster/cube_map.hpp"
#include "raster/raster.hpp"
#include "scene/scene_load.hpp"

namespace abcube {

namespace {

// shaders/abuffer_common.glsl's Setup in std430: dvec4 members on 32-byte boundaries, the
// size a multiple of 32.
struct GpuSetup {
  double edge[4][4];
  double edge3d[4][4];
  double polygon[4][4];
  double vnormal[3][4];
  double plane[4];
  double plane_distance;
  int32_t view, edge_count, ties, polygon_size;
  int32_t foot_x, foot_y, x0, y0;
  int32_t x1, y1;
  uint32_t id;
  uint32_t pad[3];
};
static_assert(sizeof(GpuSetup) == 576 && offsetof(GpuSetup, plane_distance) == 512 && offsetof(GpuSetup, id) == 560,
              "GpuSetup must match Setup in shaders/abuffer_common.glsl");

// shaders/abuffer_common.glsl's View in std430.
struct GpuView {
  double to_dir[3][4];
  double row_x[4], row_y[4], row_w[4];
  double near_distance;
  int32_t size, first_pixel;
  uint32_t pad[4];
};
static_assert(sizeof(GpuView) == 224 && offsetof(GpuView, size) == 200, "GpuView must match View");

void put(double* out, const glm::dvec3& v, double w = 0.0) {
  out[0] = v.x;
  out[1] = v.y;
  out[2] = v.z;
  out[3] = w;
}

GpuSetup pack(const TriangleSetup& s, int view) {
  GpuSetup g{};
  for (size_t k = 0; k < 4; ++k) {
    put(g.edge[k], s.edge[k]);
    put(g.edge3d[k], s.edge_3d[k]);
    put(g.polygon[k], s.polygon[k]);
    g.ties |= s.owns_ties[k] ? 1 << k : 0;
  }
  for (size_t k = 0; k < 3; ++k) put(g.vnormal[k], s.normal[k]);
  put(g.plane, s.plane_normal, s.plane_offset);
  g.plane_distance = s.plane_distance;
  g.view = view;
  g.edge_count = s.edge_count;
  g.polygon_size = s.polygon_size;
  g.foot_x = s.foot_x;
  g.foot_y = s.foot_y;
  g.x0 = s.x0;
  g.y0 = s.y0;
  g.x1 = s.x1;
  g.y1 = s.y1;
  g.id = s.triangle | (s.back_face() ? Fragment::BACK_FACE_BIT : 0u);
  return g;
}

GpuView pack(const RasterView& v, int first_pixel) {
  GpuView g{};
  for (int c = 0; c < 3; ++c) put(g.to_dir[c], v.to_direction[c]);
  put(g.row_x, v.row_x);
  put(g.row_y, v.row_y);
  put(g.row_w, v.row_w);
  g.near_distance = v.near_distance;
  g.size = v.width;
  g.first_pixel = first_pixel;
  return g;
}

// One face's visible (triangle, face) pairs, set up, and its counts for the stats.
struct FaceSetups {
  std::vector<GpuSetup> setups;
  uint64_t clipped = 0, degenerate = 0, edge_on = 0;
};

FaceSetups set_up_face(const TriangleSoup& soup, const std::vector<uint8_t>& faces_of, const RasterView& view,
                       int face) {
  FaceSetups out;
  TriangleSetup s;
  for (uint32_t t = 0; t < static_cast<uint32_t>(soup.triangle_count()); ++t) {
    if (!((faces_of[t] >> face) & 1u)) continue;
    switch (setup_triangle(view, soup, t, &s)) {
      case SetupResult::visible:
        out.setups.push_back(pack(s, face));
        out.clipped += s.near_clipped() ? 1 : 0;
        break;
      case SetupResult::degenerate: ++out.degenerate; break;
      case SetupResult::edge_on: ++out.edge_on; break;
      case SetupResult::culled: break;
    }
  }
  return out;
}

// A storage buffer, deleted with its owner.
class GlBuffer {
 public:
  GlBuffer(uint64_t bytes, const void* data) {
    glCreateBuffers(1, &id_);
    glNamedBufferData(id_, static_cast<GLsizeiptr>(std::max<uint64_t>(bytes, 4)), data, GL_DYNAMIC_COPY);
    check_gl("GPU A-buffer: a storage buffer");
  }
  ~GlBuffer() { glDeleteBuffers(1, &id_); }
  GlBuffer(const GlBuffer&) = delete;
  GlBuffer& operator=(const GlBuffer&) = delete;

  GLuint id() const { return id_; }
  void bind(unsigned binding) const { glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, id_); }
  void zero() const { glClearNamedBufferData(id_, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr); }
  template <class T>
  std::vector<T> read(size_t count) const {
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<T> out(count);
    if (count > 0) glGetNamedBufferSubData(id_, 0, static_cast<GLsizeiptr>(count * sizeof(T)), out.data());
    check_gl("GPU A-buffer: reading a buffer back");
    return out;
  }

 private:
  GLuint id_ = 0;
};

// Runs `groups` workgroups of the current program `p`, in rows of at most 65535 (the
// dispatch's guaranteed width), each program reading its index as flat_group().
void dispatch(const GlProgram& p, uint64_t groups) {
  if (groups == 0) return;
  const uint64_t row = std::min<uint64_t>(groups, 65535), rows = (groups + row - 1) / row;
  if (rows > 65535) throw RuntimeFailure("GPU A-buffer: " + std::to_string(groups) + " workgroups in one dispatch");
  glUniform1ui(p.uniform("groups_per_row"), static_cast<GLuint>(row));
  glDispatchCompute(static_cast<GLuint>(row), static_cast<GLuint>(rows), 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

// The exclusive prefix sum of `count` values of `values`, in place (abuffer_scan.comp, a
// level a recursion). Returns the total, from the first level's block sums read back and added
// in 64 bits, so that a total past 32 bits is seen.
uint64_t scan(const GlProgram& p, const GlBuffer& values, uint64_t count, bool total) {
  const uint64_t blocks = (count + ABUFFER_SCAN_BLOCK - 1) / ABUFFER_SCAN_BLOCK;
  const GlBuffer sums(blocks * sizeof(uint32_t), nullptr);
  const auto run = [&](bool add) {
    p.use();
    values.bind(ABUFFER_SCAN_VALUES_BINDING);
    sums.bind(ABUFFER_SCAN_SUMS_BINDING);
    glUniform1ui(p.uniform("value_count"), static_cast<GLuint>(count));
    glUniform1i(p.uniform("add_block_sums"), add ? 1 : 0);
    dispatch(p, blocks);
  };
  run(false);
  uint64_t sum = 0;
  if (total) {
    for (uint32_t s : sums.read<uint32_t>(blocks)) sum += s;
  }
  if (blocks > 1) {
    scan(p, sums, blocks, false);
    run(true);
  }
  return sum;
}

std::string mib(uint64_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20); }

// The kept lists (kept[p] fragments from offsets[p] of `raw`) as one ABuffer per face.
void compact_faces(const std::vector<RasterView>& rasters, const std::vector<uint32_t>& offsets,
                   const std::vector<uint32_t>& kept, const std::vector<Fragment>& raw, CubeABuffer* cube) {
  const size_t face_pixels = static_cast<size_t>(cube->n) * static_cast<size_t>(cube->n);
  for (size_t f = 0; f < CUBE_FACES; ++f) {
    ABuffer& b = cube->faces[f];
    b.view = rasters[f];
    b.offsets.assign(face_pixels + 1, 0);
    size_t total = 0;
    for (size_t p = 0; p < face_pixels; ++p) total += kept[f * face_pixels + p];
    b.fragments.resize(total);
    uint32_t write = 0;
    for (size_t p = 0; p < face_pixels; ++p) {
      const size_t g = f * face_pixels + p;
      b.offsets[p] = write;
      std::copy_n(raw.begin() + offsets[g], kept[g], b.fragments.begin() + write);
      write += kept[g];
    }
    b.offsets[face_pixels] = write;
  }
}

// The GL passes' run, from the uploaded setups to the read-back lists.
struct GpuRun {
  uint64_t raw = 0;
  uint32_t max_list = 0, dropped = 0;
  double count_ms = 0;
};

GpuRun run_passes(const SceneData& scene, const std::vector<GpuSetup>& setups, const std::vector<GpuView>& views,
                  const std::vector<RasterView>& rasters, const ABufferOptions& options, uint64_t index_bytes,
                  uint64_t budget, CubeABuffer* cube, Clock::time_point start) {
  const TriangleSoup& soup = *scene.triangles;
  const uint64_t pixels = CUBE_FACES * static_cast<uint64_t>(cube->n) * static_cast<uint64_t>(cube->n);
  std::vector<uint32_t> object_material(2 * soup.triangle_count());
  for (size_t t = 0; t < soup.triangle_count(); ++t) {
    object_material[2 * t] = soup.object_id[t];
    object_material[2 * t + 1] = soup.material_id[t];
  }
  const GlProgram count({"abuffer_common.glsl", "abuffer_count.comp"});
  const GlProgram scan_program({"abuffer_scan.comp"});
  const GlProgram fill({"abuffer_common.glsl", "abuffer_fill.comp"});
  const GlProgram finish({"abuffer_common.glsl", "abuffer_finish.comp"});
  const GlBuffer setup_buffer(setups.size() * sizeof(GpuSetup), setups.data());
  const GlBuffer view_buffer(views.size() * sizeof(GpuView), views.data());
  const GlBuffer triangles(object_material.size() * sizeof(uint32_t), object_material.data());
  const GlBuffer offsets(pixels * sizeof(uint32_t), nullptr), cursors(pixels * sizeof(uint32_t), nullptr);
  const uint32_t stats_init[2] = {0, 0};
  const GlBuffer stats(sizeof stats_init, stats_init);
  setup_buffer.bind(ABUFFER_SETUPS_BINDING);
  view_buffer.bind(ABUFFER_VIEWS_BINDING);
  offsets.zero();
  cursors.zero();

  GpuRun run;
  const auto setup_pass = [&](const GlProgram& p) {
    p.use();
    setup_buffer.bind(ABUFFER_SETUPS_BINDING);
    view_buffer.bind(ABUFFER_VIEWS_BINDING);
    glUniform1d(p.uniform("trivial_rel"), RASTER_TRIVIAL_REL);
    glUniform1ui(p.uniform("setup_count"), static_cast<GLuint>(setups.size()));
    dispatch(p, setups.size());
  };
  offsets.bind(ABUFFER_OFFSETS_BINDING);
  setup_pass(count);
  run.raw = scan(scan_program, offsets, pixels, true);
  run.count_ms = ms_since(start);
  if (run.raw > std::numeric_limits<uint32_t>::max()) {
    throw InputError("cube A-buffer (GPU): more than 2^32 fragments (" + std::to_string(run.raw) +
                     "); lower --cube-res");
  }
  // The fragments twice (the GPU's array and its copy read back) and the per-pixel index.
  const uint64_t estimate = index_bytes + 2 * run.raw * sizeof(Fragment);
  check_abuffer_budget("cube A-buffer (GPU)", estimate,
                       std::to_string(run.raw) + " fragments at " + std::to_string(sizeof(Fragment)) +
                           " bytes, on the GPU and read back, and " + mib(index_bytes) + " MiB of set-up and index",
                       options, budget);
  const GlBuffer fragments(run.raw * sizeof(Fragment), nullptr);
  offsets.bind(ABUFFER_OFFSETS_BINDING);
  cursors.bind(ABUFFER_CURSORS_BINDING);
  fragments.bind(ABUFFER_FRAGMENTS_BINDING);
  setup_pass(fill);

  finish.use();
  triangles.bind(ABUFFER_TRIANGLES_BINDING);
  stats.bind(ABUFFER_STATS_BINDING);
  glUniform1ui(finish.uniform("pixel_count"), static_cast<GLuint>(pixels));
  glUniform1ui(finish.uniform("centre_samples"), CENTRE_SAMPLES);
  glUniform1d(finish.uniform("merge_min_cos"), MERGE_MIN_NORMAL_COS);
  glUniform1i(finish.uniform("merge"), options.merge ? 1 : 0);
  glUniform1ui(finish.uniform("max_layers"), options.max_layers);
  dispatch(finish, (pixels + 63) / 64);
  check_gl("GPU A-buffer passes");

  const std::vector<uint32_t> stat_values = stats.read<uint32_t>(2);
  run.max_list = stat_values[0];
  run.dropped = stat_values[1];
  compact_faces(rasters, offsets.read<uint32_t>(pixels), cursors.read<uint32_t>(pixels),
                fragments.read<Fragment>(run.raw), cube);
  return run;
}

}  // namespace

CubeABuffer build_cube_abuffer_gl(const SceneData& scene, const glm::dvec3& centre, int n,
                                  const ABufferOptions& options, ABufferStats* stats) {
  if (n < 1) throw InputError("cube A-buffer (GPU): resolution must be >= 1, got " + std::to_string(n));
  if (!std::isfinite(centre.x) || !std::isfinite(centre.y) || !std::isfinite(centre.z)) {
    throw InputError("cube A-buffer (GPU): the centre must be finite");
  }
  const Clock::time_point start = Clock::now();
  const double near = abuffer_near_distance(scene, centre, options);
  const TriangleSoup& soup = *scene.triangles;
  CubeABuffer cube;
  cube.n = n;
  cube.centre = centre;
  cube.near_distance = near;
  const uint64_t face_pixels = static_cast<uint64_t>(n) * static_cast<uint64_t>(n);
  const uint64_t budget = memory_budget_bytes(options.max_memory_bytes);
  // The per-pixel offsets and cursors on the GPU and read back: the index alone first.
  uint64_t index_bytes = 4 * CUBE_FACES * face_pixels * sizeof(uint32_t);
  check_abuffer_budget("cube A-buffer (GPU)", index_bytes, "its per-pixel index alone", options, budget);

  std::vector<RasterView> rasters;
  std::vector<GpuView> views;
  for (int f = 0; f < CUBE_FACES; ++f) {
    rasters.push_back(cube_face_view(f, centre, n, near));
    views.push_back(pack(rasters.back(), static_cast<int>(f * face_pixels)));
  }
  const std::vector<uint8_t> faces_of = triangle_cube_faces(soup, centre, options.threads);
  std::vector<FaceSetups> faces(CUBE_FACES);
  const int threads = thread_count(options.threads, CUBE_FACES);
  parallel_for(CUBE_FACES, threads,
               [&](size_t f, int) { faces[f] = set_up_face(soup, faces_of, rasters[f], static_cast<int>(f)); });
  std::vector<GpuSetup> setups;
  ABufferStats st;
  for (const FaceSetups& f : faces) {
    setups.insert(setups.end(), f.setups.begin(), f.setups.end());
    st.triangles_clipped += f.clipped;
  }
  st.triangles_degenerate = faces.front().degenerate;  // every face counts them (triangle_cube_faces)
  st.triangles_edge_on = faces.front().edge_on;
  faces = std::vector<FaceSetups>();
  index_bytes += setups.size() * sizeof(GpuSetup) + soup.triangle_count() * 2 * sizeof(uint32_t);

  const GpuRun run = run_passes(scene, setups, views, rasters, options, index_bytes, budget, &cube, start);
  if (stats) {
    std::vector<unsigned char> seen(soup.triangle_count(), 0);
    for (const GpuSetup& s : setups) seen[s.id & ~Fragment::BACK_FACE_BIT] = 1;
    const uint64_t unbinned = static_cast<uint64_t>(std::count(seen.begin(), seen.end(), 0));
    st.triangle_views = setups.size();
    st.triangles_culled = unbinned - st.triangles_degenerate - st.triangles_edge_on;
    st.raw_fragments = run.raw;
    st.max_list_length = run.max_list;
    st.dropped_by_cap = run.dropped;
    for (const ABuffer& b : cube.faces) {
      st.fragments_per_view.push_back(b.fragments.size());
      st.fragments += b.fragments.size();
      st.bytes_total += b.fragments.size() * sizeof(Fragment) + b.offsets.size() * sizeof(uint32_t);
    }
    st.estimated_bytes = index_bytes + 2 * run.raw * sizeof(Fragment);
    st.budget_bytes = budget;
    st.near_distance = near;
    st.count_ms = run.count_ms;
    st.total_ms = ms_since(start);
    st.fill_ms = st.total_ms - run.count_ms;
    st.threads = threads;
    *stats = std::move(st);
  }
  return cube;
}

}  // namespace abcube
