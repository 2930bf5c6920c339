#include "gl/gl_abuffer.hpp"

#include <glad/gl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "gl/gl_compute.hpp"
#include "gl/gl_view.hpp"
#include "gl/gl_program.hpp"
#include "gl/glsl_shared.hpp"
#include "raster/cube_map.hpp"
#include "raster/raster.hpp"
#include "scene/camera.hpp"
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

// One view's visible (triangle, view) pairs, set up, and its counts for the stats.
struct ViewSetups {
  std::vector<GpuSetup> setups;
  uint64_t clipped = 0, degenerate = 0, edge_on = 0;
};

// `views_of` (optional, one byte a triangle, as the CPU build's): bit `v` clear where view `v`
// is known to cover none of the triangle's samples, which is then culled unset up.
ViewSetups set_up_view(const TriangleSoup& soup, const uint8_t* views_of, const RasterView& view, int v) {
  ViewSetups out;
  TriangleSetup s;
  for (uint32_t t = 0; t < static_cast<uint32_t>(soup.triangle_count()); ++t) {
    if (views_of && !((views_of[t] >> v) & 1u)) continue;
    switch (setup_triangle(view, soup, t, &s)) {
      case SetupResult::visible:
        out.setups.push_back(pack(s, v));
        out.clipped += s.near_clipped() ? 1 : 0;
        break;
      case SetupResult::degenerate: ++out.degenerate; break;
      case SetupResult::edge_on: ++out.edge_on; break;
      case SetupResult::culled: break;
    }
  }
  return out;
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

// The count and fill passes' work items: (setup, tile) for every ABUFFER_TILE-square tile
// of each setup's pixel bounds, so that no invocation walks more than a tile.
std::vector<uint32_t> work_items(const std::vector<GpuSetup>& setups) {
  std::vector<uint32_t> items;
  for (uint32_t i = 0; i < static_cast<uint32_t>(setups.size()); ++i) {
    const GpuSetup& s = setups[i];
    const uint32_t across = static_cast<uint32_t>((s.x1 - s.x0 + ABUFFER_TILE - 1) / ABUFFER_TILE);
    const uint32_t down = static_cast<uint32_t>((s.y1 - s.y0 + ABUFFER_TILE - 1) / ABUFFER_TILE);
    for (uint32_t t = 0; t < across * down; ++t) items.insert(items.end(), {i, t});
  }
  return items;
}

// What one build is: its views in the build's pixel order (view v from first_pixel[v]), the
// views each triangle may cover (optional), and the words of its errors.
struct ViewSet {
  std::vector<RasterView> rasters;
  std::vector<uint64_t> first_pixel;
  uint64_t pixels = 0;
  const std::vector<uint8_t>* views_of = nullptr;
  const char* what;   // "cube A-buffer (GPU)"
  const char* lower;  // the option that lowers its size
};

ViewSet view_set(std::vector<RasterView> rasters, const char* what, const char* lower) {
  ViewSet set{std::move(rasters), {}, 0, nullptr, what, lower};
  for (const RasterView& r : set.rasters) {
    set.first_pixel.push_back(set.pixels);
    set.pixels += r.pixel_count();
  }
  return set;
}

// The lists longer than ABUFFER_GPU_LIST_MAX, which the finish pass left as filled,
// finished by the CPU's rule in `raw`: their kept counts into `kept`, the cap's drops into
// *dropped, the longest into *max_list.
void finish_long_lists(const TriangleSoup& soup, const ABufferOptions& options, const std::vector<uint32_t>& offsets,
                       std::vector<uint32_t>* kept, std::vector<Fragment>* raw, uint64_t* dropped, uint32_t* max_list) {
  for (size_t p = 0; p < offsets.size(); ++p) {
    const uint32_t count = (*kept)[p];
    if (count <= ABUFFER_GPU_LIST_MAX) continue;
    (*kept)[p] = finish_fragment_list(soup, options, raw->data() + offsets[p], count, dropped);
    *max_list = std::max(*max_list, (*kept)[p]);
  }
}

// The kept lists (kept[p] fragments from offsets[p] of `raw`) as one ABuffer per view.
std::vector<ABuffer> compact_views(const ViewSet& set, const std::vector<uint32_t>& offsets,
                                   const std::vector<uint32_t>& kept, const std::vector<Fragment>& raw) {
  std::vector<ABuffer> out(set.rasters.size());
  for (size_t v = 0; v < out.size(); ++v) {
    ABuffer& b = out[v];
    b.view = set.rasters[v];
    const size_t first = set.first_pixel[v], pixels = b.view.pixel_count();
    b.offsets.assign(pixels + 1, 0);
    size_t total = 0;
    for (size_t p = 0; p < pixels; ++p) total += kept[first + p];
    b.fragments.resize(total);
    uint32_t write = 0;
    for (size_t p = 0; p < pixels; ++p) {
      const size_t g = first + p;
      b.offsets[p] = write;
      std::copy_n(raw.begin() + offsets[g], kept[g], b.fragments.begin() + write);
      write += kept[g];
    }
    b.offsets[pixels] = write;
  }
  return out;
}

// The GL passes' run, from the uploaded setups to the read-back lists.
struct GpuRun {
  std::vector<ABuffer> views;
  uint64_t raw = 0, dropped = 0;
  uint32_t max_list = 0;
  double count_ms = 0;
};

}  // namespace

struct GlABufferBuilder::Programs {
  GlProgram count{std::vector<const char*>{"double_math.glsl", "fragment.glsl", "view.glsl", "abuffer_common.glsl",
                                           "abuffer_count.comp"}};
  GlProgram scan{std::vector<const char*>{"abuffer_scan.comp"}};
  GlProgram fill{std::vector<const char*>{"double_math.glsl", "fragment.glsl", "view.glsl", "abuffer_common.glsl",
                                          "abuffer_fill.comp"}};
  GlProgram finish{std::vector<const char*>{"double_math.glsl", "fragment.glsl", "view.glsl", "abuffer_common.glsl",
                                            "abuffer_finish.comp"}};
};

namespace {

GpuRun run_passes(const GlABufferBuilder::Programs& programs, const SceneData& scene,
                  const std::vector<GpuSetup>& setups, const std::vector<uint32_t>& items, const ViewSet& set,
                  const ABufferOptions& options, uint64_t index_bytes, uint64_t budget, Clock::time_point start) {
  const TriangleSoup& soup = *scene.triangles;
  const uint64_t pixels = set.pixels;
  std::vector<GpuView> views;
  for (size_t v = 0; v < set.rasters.size(); ++v)
    views.push_back(gpu_view(set.rasters[v], static_cast<int>(set.first_pixel[v])));
  std::vector<uint32_t> object_material(2 * soup.triangle_count());
  for (size_t t = 0; t < soup.triangle_count(); ++t) {
    object_material[2 * t] = soup.object_id[t];
    object_material[2 * t + 1] = soup.material_id[t];
  }
  const GlBuffer setup_buffer(setups.size() * sizeof(GpuSetup), setups.data());
  const GlBuffer item_buffer(items.size() * sizeof(uint32_t), items.data());
  const GlBuffer view_buffer(views.size() * sizeof(GpuView), views.data());
  const GlBuffer triangles(object_material.size() * sizeof(uint32_t), object_material.data());
  const GlBuffer offsets(pixels * sizeof(uint32_t), nullptr), cursors(pixels * sizeof(uint32_t), nullptr);
  const uint32_t stats_init[2] = {0, 0};
  const GlBuffer stats(sizeof stats_init, stats_init);
  offsets.zero();
  cursors.zero();

  GpuRun run;
  const auto setup_pass = [&](const GlProgram& p) {
    p.use();
    setup_buffer.bind(ABUFFER_SETUPS_BINDING);
    item_buffer.bind(ABUFFER_ITEMS_BINDING);
    view_buffer.bind(ABUFFER_VIEWS_BINDING);
    glUniform1d(p.uniform("trivial_rel"), RASTER_TRIVIAL_REL);
    glUniform1ui(p.uniform("item_count"), static_cast<GLuint>(items.size() / 2));
    dispatch(p, (items.size() / 2 + 63) / 64);
  };
  offsets.bind(ABUFFER_OFFSETS_BINDING);
  setup_pass(programs.count);
  run.raw = scan(programs.scan, offsets, pixels, true);
  run.count_ms = ms_since(start);
  if (run.raw > std::numeric_limits<uint32_t>::max()) {  // the offsets are 32 bits
    throw InputError(std::string(set.what) + ": more than 2^32 fragments (" + std::to_string(run.raw) + "); lower " +
                     set.lower);
  }
  // The fragments twice (the GPU's array and its copy read back) and the per-pixel index.
  const uint64_t estimate = index_bytes + 2 * run.raw * sizeof(Fragment);
  check_abuffer_budget(set.what, estimate,
                       std::to_string(run.raw) + " fragments at " + std::to_string(sizeof(Fragment)) +
                           " bytes, on the GPU and read back, and " + mib(index_bytes) + " MiB of set-up and index",
                       options, budget);
  const GlBuffer fragments(run.raw * sizeof(Fragment), nullptr);
  offsets.bind(ABUFFER_OFFSETS_BINDING);
  cursors.bind(ABUFFER_CURSORS_BINDING);
  fragments.bind(ABUFFER_FRAGMENTS_BINDING);
  setup_pass(programs.fill);

  const GlProgram& finish = programs.finish;
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
  const std::vector<uint32_t> starts = offsets.read<uint32_t>(pixels);
  std::vector<uint32_t> kept = cursors.read<uint32_t>(pixels);
  std::vector<Fragment> raw = fragments.read<Fragment>(run.raw);
  finish_long_lists(soup, options, starts, &kept, &raw, &run.dropped, &run.max_list);
  run.views = compact_views(set, starts, kept, raw);
  return run;
}

// The lists of every view of `set` (build_views of raster/abuffer.cpp, on the GPU).
std::vector<ABuffer> build_views_gl(const GlABufferBuilder::Programs& programs, const SceneData& scene,
                                    const ViewSet& set, const ABufferOptions& options, ABufferStats* stats) {
  const Clock::time_point start = Clock::now();
  const TriangleSoup& soup = *scene.triangles;
  const uint64_t budget = memory_budget_bytes(options.max_memory_bytes);
  // The per-pixel offsets and cursors on the GPU and read back: the index alone first.
  uint64_t index_bytes = 4 * set.pixels * sizeof(uint32_t);
  check_abuffer_budget(set.what, index_bytes, "its per-pixel index alone", options, budget);

  std::vector<ViewSetups> per_view(set.rasters.size());
  const int threads = thread_count(options.threads, per_view.size());
  const uint8_t* views_of = set.views_of ? set.views_of->data() : nullptr;
  parallel_for(per_view.size(), threads,
               [&](size_t v, int) { per_view[v] = set_up_view(soup, views_of, set.rasters[v], static_cast<int>(v)); });
  std::vector<GpuSetup> setups;
  ABufferStats st;
  for (const ViewSetups& v : per_view) {
    setups.insert(setups.end(), v.setups.begin(), v.setups.end());
    st.triangles_clipped += v.clipped;
  }
  st.triangles_degenerate = per_view.front().degenerate;  // every view counts them (as the CPU's bins)
  st.triangles_edge_on = per_view.front().edge_on;
  per_view = std::vector<ViewSetups>();
  const std::vector<uint32_t> items = work_items(setups);
  index_bytes +=
      setups.size() * sizeof(GpuSetup) + items.size() * sizeof(uint32_t) + soup.triangle_count() * 2 * sizeof(uint32_t);

  GpuRun run = run_passes(programs, scene, setups, items, set, options, index_bytes, budget, start);
  if (stats) {
    std::vector<unsigned char> seen(soup.triangle_count(), 0);
    for (const GpuSetup& s : setups) seen[s.id & ~Fragment::BACK_FACE_BIT] = 1;
    const uint64_t unbinned = static_cast<uint64_t>(std::count(seen.begin(), seen.end(), 0));
    st.triangle_views = setups.size();
    st.triangles_culled = unbinned - st.triangles_degenerate - st.triangles_edge_on;
    st.raw_fragments = run.raw;
    st.max_list_length = run.max_list;
    st.dropped_by_cap = run.dropped;
    for (const ABuffer& b : run.views) {
      st.fragments_per_view.push_back(b.fragments.size());
      st.fragments += b.fragments.size();
      st.bytes_total += b.fragments.size() * sizeof(Fragment) + b.offsets.size() * sizeof(uint32_t);
    }
    st.estimated_bytes = index_bytes + 2 * run.raw * sizeof(Fragment);
    st.budget_bytes = budget;
    st.near_distance = set.rasters.front().near_distance;
    st.count_ms = run.count_ms;
    st.total_ms = ms_since(start);
    st.fill_ms = st.total_ms - run.count_ms;
    st.threads = threads;
    *stats = std::move(st);
  }
  return std::move(run.views);
}

}  // namespace

GlABufferBuilder::GlABufferBuilder() {
  require_storage_bindings("GPU A-buffer", ABUFFER_ITEMS_BINDING);
  programs_ = std::make_unique<Programs>();
}
GlABufferBuilder::~GlABufferBuilder() = default;

CubeABuffer GlABufferBuilder::cube(const SceneData& scene, const glm::dvec3& centre, int n,
                                   const ABufferOptions& options, ABufferStats* stats) const {
  const char* what = "cube A-buffer (GPU)";
  ViewSet set = view_set(cube_build_views(what, scene, centre, n, options), what, "--cube-res");
  const double near = set.rasters.front().near_distance;
  const std::vector<uint8_t> faces_of = triangle_cube_faces(*scene.triangles, centre, options.threads);
  set.views_of = &faces_of;
  return cube_of_faces(n, centre, near, build_views_gl(*programs_, scene, set, options, stats));
}

ABuffer GlABufferBuilder::camera(const SceneData& scene, const ABufferOptions& options, ABufferStats* stats) const {
  const CameraFrame frame = make_camera_frame(scene.camera);
  const double near = abuffer_near_distance(scene, frame.eye, options);
  const ViewSet set = view_set({camera_view(frame, near)}, "camera A-buffer (GPU)", "the image size");
  std::vector<ABuffer> one = build_views_gl(*programs_, scene, set, options, stats);
  return std::move(one.front());
}

CubeABuffer build_cube_abuffer_gl(const SceneData& scene, const glm::dvec3& centre, int n,
                                  const ABufferOptions& options, ABufferStats* stats) {
  return GlABufferBuilder().cube(scene, centre, n, options, stats);
}

}  // namespace abcube
