#include "gl/gl_cube_scan.hpp"

#include <glad/gl.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <sstream>
#include <utility>

#include "base/error.hpp"
#include "gl/gl_compute.hpp"
#include "gl/gl_cube_walks.hpp"
#include "gl/gl_program.hpp"
#include "gl/glsl_shared.hpp"
#include "material/shading.hpp"

namespace abcube {

namespace {

// shaders/cube_scan.comp's ScanRay in std430 (a dvec4 member: 32-byte aligned, size a
// multiple of 32).
struct GpuScanRay {
  double w_lmax[4];
  double d_self[4];
  uint32_t object_row[4];
  double self_tolerance[2];
};
// Its CandidateOut, after the count and three pad words (the array is 16-byte aligned).
struct GpuCandidate {
  uint32_t texel, fragment, ray, id;
  double l, outside;
  double interval[2];
  uint32_t flags, triangle, mesh_tested, ij;
  double before_l1, pad;
};
static_assert(sizeof(GpuScanRay) == 96 && sizeof(GpuCandidate) == 80, "must match shaders/scan_common.glsl");
constexpr uint64_t CANDIDATES_AT = 16;  // bytes before the first candidate
static_assert(sizeof(Fragment) == 20, "cube_scan.comp reads fragments as 20 bytes");
constexpr uint32_t NO_ROW = 0xffffffffu;

// Throws RuntimeFailure unless `bytes` of `what` fit one storage block.
void check_block(const char* what, uint64_t bytes) {
  require_block_bytes(std::string("GPU candidate scan: ") + what, bytes, "lower N or scan on the CPU");
}

// cube_scan_walks.comp's RayScanOut.
struct GpuRayScan {
  uint32_t texels, flags, pad0, pad1;
  double last_l1, pad;
};
static_assert(sizeof(GpuRayScan) == 32, "must match shaders/cube_scan_walks.comp");
// Its flags.
constexpr uint32_t SCAN_CAPPED = 1, SCAN_ENDED = 2, SCAN_STOPPED = 4, SCAN_OVER_BUDGET = 8, SCAN_LOOPS_RAN = 16;

}  // namespace

struct GlCandidateScan::Buffers {
  GlProgram walk_scan{std::vector<const char*>{"double_math.glsl", "cube_walk.glsl", "scan_common.glsl",
                                               "triangle_geometry.glsl", "fragment.glsl", "scan_lists.glsl",
                                               "cube_scan_walks.comp"}};
  GlProgram program{std::vector<const char*>{"double_math.glsl", "cube_walk.glsl", "scan_common.glsl", "fragment.glsl",
                                             "scan_lists.glsl", "cube_scan.comp"}};
  GlProgram refine{std::vector<const char*>{"double_math.glsl", "cube_walk.glsl", "scan_common.glsl",
                                            "triangle_geometry.glsl", "mesh_refine.glsl", "cube_refine.comp"}};
  GlCubeWalks walks;
  std::unique_ptr<GlBuffer> lists, fragments, planes, positions, neighbours, blocks;
  int blocks_per_row = 0;
  std::vector<uint32_t> objects;     // per triangle its object
  std::vector<uint32_t> opaque;      // bit t: triangle t lets no light through (blocker_transmittance 0)
  std::vector<uint32_t> face_first;  // each face's first fragment in `fragments`, then the total
};

GlCandidateScan::GlCandidateScan(const SearchContext& ctx) : ctx_(&ctx) {
  require_storage_bindings("GPU candidate scan", CUBE_SCAN_POSITIONS_BINDING);
  require_compute_blocks("GPU candidate scan", 9);
  buffers_ = std::make_unique<Buffers>();
  Buffers& b = *buffers_;
  const CubeABuffer& cube = ctx.cube();
  const size_t face_texels = static_cast<size_t>(cube.n) * static_cast<size_t>(cube.n);
  std::vector<uint32_t> lists(CUBE_FACES * face_texels + 1);
  uint64_t total = 0;
  for (int f = 0; f < CUBE_FACES; ++f) {
    const ABuffer& face = cube.faces[static_cast<size_t>(f)];
    b.face_first.push_back(static_cast<uint32_t>(total));
    for (size_t p = 0; p < face_texels; ++p) {
      const uint32_t length = face.offsets[p + 1] - face.offsets[p];
      if (length > GPU_SCAN_MAX_LIST) {
        throw RuntimeFailure("GPU candidate scan: a list of " + std::to_string(length) + " fragments, above the " +
                             std::to_string(GPU_SCAN_MAX_LIST) + " one invocation reads");
      }
      lists[static_cast<size_t>(f) * face_texels + p] = static_cast<uint32_t>(total + face.offsets[p]);
    }
    total += face.fragments.size();
  }
  b.face_first.push_back(static_cast<uint32_t>(total));
  lists.back() = static_cast<uint32_t>(total);
  check_block("the lists' offsets", lists.size() * sizeof(uint32_t));
  check_block("the fragments", total * sizeof(Fragment));
  b.lists = std::make_unique<GlBuffer>(lists.size() * sizeof(uint32_t), lists.data());
  b.fragments = std::make_unique<GlBuffer>(total * sizeof(Fragment), nullptr);
  for (int f = 0; f < CUBE_FACES; ++f) {
    const std::vector<Fragment>& frags = cube.faces[static_cast<size_t>(f)].fragments;
    if (frags.empty()) continue;
    glNamedBufferSubData(b.fragments->id(),
                         static_cast<GLintptr>(b.face_first[static_cast<size_t>(f)] * sizeof(Fragment)),
                         static_cast<GLsizeiptr>(frags.size() * sizeof(Fragment)), frags.data());
  }
  const TriangleSoup& soup = *ctx.scene().triangles;
  std::vector<double> planes(4 * soup.triangle_count());
  for (uint32_t t = 0; t < static_cast<uint32_t>(soup.triangle_count()); ++t) {
    const SearchContext::Plane p = ctx.plane(t);
    planes[4 * t] = p.normal.x, planes[4 * t + 1] = p.normal.y, planes[4 * t + 2] = p.normal.z;
    planes[4 * t + 3] = p.offset;
  }
  check_block("the triangles' planes", planes.size() * sizeof(double));
  check_block("the triangles' vertices", soup.positions.size() * sizeof(glm::vec3));
  b.planes = std::make_unique<GlBuffer>(planes.size() * sizeof(double), planes.data());
  b.positions = std::make_unique<GlBuffer>(soup.positions.size() * sizeof(glm::vec3), soup.positions.data());
  std::vector<uint32_t> neighbours(3 * soup.triangle_count());
  for (uint32_t t = 0; t < static_cast<uint32_t>(soup.triangle_count()); ++t) {
    for (int k = 0; k < 3; ++k) neighbours[3 * t + static_cast<uint32_t>(k)] = ctx.neighbour(t, k);
  }
  check_block("the triangles' neighbours", neighbours.size() * sizeof(uint32_t));
  b.neighbours = std::make_unique<GlBuffer>(neighbours.size() * sizeof(uint32_t), neighbours.data());
  // BLOCK BOUNDS, as the search context holds them: face by face, row by row.
  b.blocks_per_row = (cube.n + SearchContext::BOUNDS_BLOCK - 1) / SearchContext::BOUNDS_BLOCK;
  std::vector<glm::vec2> blocks;
  for (int f = 0; f < CUBE_FACES; ++f) {
    for (int bj = 0; bj < b.blocks_per_row; ++bj) {
      for (int bi = 0; bi < b.blocks_per_row; ++bi) {
        blocks.push_back(ctx.node_bounds(f, 0, bi * SearchContext::BOUNDS_BLOCK, bj * SearchContext::BOUNDS_BLOCK));
      }
    }
  }
  check_block("the block bounds", blocks.size() * sizeof(glm::vec2));
  b.blocks = std::make_unique<GlBuffer>(blocks.size() * sizeof(glm::vec2), blocks.data());
  b.objects = soup.object_id;
  b.opaque.assign((soup.triangle_count() + 31) / 32, 0u);
  for (uint32_t t = 0; t < static_cast<uint32_t>(soup.triangle_count()); ++t) {
    if (blocker_transmittance(ctx.scene().materials[soup.material_id[t]]) == glm::dvec3(0.0)) {
      b.opaque[t / 32] |= 1u << (t % 32);
    }
  }
  check_gl("GPU candidate scan: uploading the lists");
}

GlCandidateScan::~GlCandidateScan() = default;

uint64_t GlCandidateScan::upload_bytes(const SearchContext& ctx) {
  const CubeABuffer& cube = ctx.cube();
  uint64_t fragments = 0;
  for (const ABuffer& face : cube.faces) fragments += face.fragments.size();
  const uint64_t texels = static_cast<uint64_t>(CUBE_FACES) * static_cast<uint64_t>(cube.n) * cube.n;
  const uint64_t triangles = ctx.scene().triangles->triangle_count();
  const uint64_t blocks_per_row =
      (static_cast<uint64_t>(cube.n) + SearchContext::BOUNDS_BLOCK - 1) / SearchContext::BOUNDS_BLOCK;
  const uint64_t block_bytes = 2 * CUBE_FACES * blocks_per_row * blocks_per_row * sizeof(glm::vec2);
  // The offsets (uploaded from a host copy), the fragments, the block bounds (and their host
  // copy); a triangle's plane (4 doubles, and
  // its host copy), vertices, neighbours (and their host copy), object (host) and opaque bit.
  return 2 * (texels + 1) * sizeof(uint32_t) + fragments * sizeof(Fragment) + block_bytes +
         triangles * (2 * 4 * sizeof(double) + 9 * sizeof(float) + 2 * 3 * sizeof(uint32_t) + sizeof(uint32_t) + 1);
}

namespace {

// The rows of the restricted rays' objects (Media::bounds_meet), appended to `objects`: one
// row a distinct object, a bit an object of the scene. Sets each ray's row.
void add_restriction_rows(const SearchContext& ctx, const std::vector<SearchRay>& rays, std::vector<GpuScanRay>* packed,
                          std::vector<uint32_t>* objects, uint32_t* row_words) {
  const uint32_t count = static_cast<uint32_t>(ctx.scene().objects.size());
  *row_words = (count + 31) / 32;
  std::map<uint32_t, uint32_t> row_of;
  for (size_t k = 0; k < rays.size(); ++k) {
    if (!rays[k].restrict_object) continue;
    const auto [at, added] = row_of.emplace(rays[k].object, static_cast<uint32_t>(row_of.size()));
    (*packed)[k].object_row[1] = at->second;
    if (!added) continue;
    const size_t first = objects->size();
    objects->resize(first + *row_words, 0u);
    for (uint32_t o = 0; o < count; ++o) {
      if (ctx.media().bounds_meet(o, rays[k].object)) (*objects)[first + o / 32] |= 1u << (o % 32);
    }
  }
}

// A candidate read back (its fragment: of all faces) as the walk's texel `texel` of its ray.
ScanCandidate unpacked_candidate(const GpuCandidate& g, uint32_t texel, const std::vector<uint32_t>& face_first) {
  const uint32_t fragment = g.fragment;
  const size_t face =
      static_cast<size_t>(std::upper_bound(face_first.begin(), face_first.end(), fragment) - face_first.begin()) - 1;
  ScanCandidate c;
  c.texel = texel, c.face = static_cast<uint32_t>(face), c.fragment = fragment - face_first[face];
  c.i = static_cast<int>(g.ij & 0xffffu), c.j = static_cast<int>(g.ij >> 16);
  c.l1 = g.interval[1], c.before_l1 = g.before_l1;
  c.tested = (g.flags & 1u) != 0, c.exact = (g.flags & 2u) != 0, c.valid = (g.flags & 4u) != 0;
  c.back_face = (g.flags & 8u) != 0;
  c.triangle = g.triangle, c.l = g.l, c.outside = g.outside, c.mesh_triangles = g.mesh_tested;
  return c;
}

// Batch b's candidates, read back with the batch's texel and the fragment of all, into
// out[b.chunk + b.first ...]: in the walk's order (texel, then the list's).
void unpack_candidates(std::vector<GpuCandidate> found, const GlCubeWalks::Batch& b,
                       const std::vector<uint32_t>& face_first, CandidateScan* out) {
  std::sort(found.begin(), found.end(), [](const GpuCandidate& x, const GpuCandidate& y) {
    return x.texel != y.texel ? x.texel < y.texel : x.fragment < y.fragment;
  });
  for (const GpuCandidate& g : found) {
    const size_t k =
        static_cast<size_t>(std::upper_bound(b.offsets.begin(), b.offsets.end(), g.texel) - b.offsets.begin()) - 1;
    out[b.chunk + b.first + k].candidates.push_back(unpacked_candidate(g, g.texel - b.offsets[k], face_first));
  }
}

}  // namespace

namespace {

// What a batch's pass reads beside the uploaded scene: its rays, the objects with their
// restriction rows, and the search's tolerance.
struct BatchInputs {
  const GlBuffer* rays;
  const GlBuffer* objects;
  uint32_t rows_at, row_words;
  double tolerance_texels;
  bool refine_mesh;
};

// Each found candidate's crossing test (cube_refine.comp), in place.
void run_crossing_tests(const GlCandidateScan::Buffers& b, const CubeABuffer& cube, const BatchInputs& in,
                        const GlBuffer& found, uint32_t count) {
  const GlProgram& p = b.refine;
  p.use();
  in.rays->bind(CUBE_SCAN_RAYS_BINDING);
  found.bind(CUBE_SCAN_CANDIDATES_BINDING);
  b.positions->bind(CUBE_SCAN_POSITIONS_BINDING);
  b.neighbours->bind(CUBE_REFINE_NEIGHBOURS_BINDING);
  glUniform3d(p.uniform("centre"), cube.centre.x, cube.centre.y, cube.centre.z);
  glUniform1i(p.uniform("face_resolution"), cube.n);
  glUniform1d(p.uniform("on_triangle_texels"), ON_TRIANGLE_TEXELS);
  glUniform1d(p.uniform("tolerance_texels"), in.tolerance_texels);
  glUniform1i(p.uniform("refine_mesh"), in.refine_mesh ? 1 : 0);
  dispatch(p, (count + 63) / 64);
  check_gl("GPU candidates' crossing tests");
}

// A scan pass: program p with the lists, the batch's inputs and the candidates bound, and what
// `bind_own` binds, over `invocations` invocations; first with room for `room` candidates (at
// most what one storage block holds), then, when it found more, with room for all. Then each
// candidate's crossing test; the candidates read back, in the order found.
std::vector<GpuCandidate> scan_pass(const GlCandidateScan::Buffers& b, const CubeABuffer& cube, const BatchInputs& in,
                                    const GlProgram& p, uint64_t room, uint64_t invocations,
                                    const std::function<void()>& bind_own) {
  room = std::max<uint64_t>(1, std::min(room, (max_block_bytes() - CANDIDATES_AT) / sizeof(GpuCandidate)));
  for (;;) {
    const uint64_t bytes = CANDIDATES_AT + sizeof(GpuCandidate) * room;
    check_block("one pass's candidates", bytes);
    const GlBuffer found(bytes, nullptr);
    found.zero();
    p.use();
    in.rays->bind(CUBE_SCAN_RAYS_BINDING);
    b.lists->bind(CUBE_SCAN_LISTS_BINDING);
    b.fragments->bind(CUBE_SCAN_FRAGMENTS_BINDING);
    b.planes->bind(CUBE_SCAN_PLANES_BINDING);
    in.objects->bind(CUBE_SCAN_OBJECTS_BINDING);
    found.bind(CUBE_SCAN_CANDIDATES_BINDING);
    glUniform1i(p.uniform("face_resolution"), cube.n);
    glUniform1ui(p.uniform("rows_at"), in.rows_at);
    glUniform1ui(p.uniform("row_words"), in.row_words);
    glUniform1ui(p.uniform("candidate_room"), static_cast<GLuint>(room));
    bind_own();
    dispatch(p, (invocations + 63) / 64);
    check_gl("GPU candidate scan");
    const uint32_t count = found.read<uint32_t>(1)[0];
    if (count > room) {
      room = count;
      continue;
    }
    run_crossing_tests(b, cube, in, found, count);
    const std::vector<unsigned char> read = found.read<unsigned char>(CANDIDATES_AT + sizeof(GpuCandidate) * count);
    std::vector<GpuCandidate> candidates(count);
    if (count > 0) std::memcpy(candidates.data(), read.data() + CANDIDATES_AT, sizeof(GpuCandidate) * count);
    return candidates;
  }
}

// The candidates of one batch of walks left on the GPU, an invocation a texel (cube_scan.comp).
std::vector<GpuCandidate> scan_batch(const GlCandidateScan::Buffers& b, const CubeABuffer& cube, const BatchInputs& in,
                                     const GlCubeWalks::Batch& batch, uint64_t room) {
  const GlProgram& p = b.program;
  return scan_pass(b, cube, in, p, room, batch.texel_count, [&] {
    batch.texels->bind(CUBE_WALK_TEXELS_BINDING);
    batch.offset_buffer->bind(CUBE_WALK_OFFSETS_BINDING);
    glUniform1ui(p.uniform("first_ray"), 0u);
    glUniform1ui(p.uniform("ray_count"), static_cast<GLuint>(batch.end - batch.first));
    glUniform1ui(p.uniform("texel_count"), static_cast<GLuint>(batch.texel_count));
  });
}

// The candidates of `count` rays (uploaded in `in`), each walked and scanned by one invocation
// (cube_scan_walks.comp): per ray its walk's summary, and the candidates found.
struct WalkingScan {
  std::vector<GpuRayScan> rays;
  std::vector<GpuCandidate> candidates;
};
WalkingScan scan_walking(const GlCandidateScan::Buffers& b, const CubeABuffer& cube, const BatchInputs& in,
                         uint32_t cap, size_t count, uint32_t opaque_at, const ScanBatching& batching) {
  const GlProgram& p = b.walk_scan;
  check_block("one pass's rays", count * sizeof(GpuRayScan));
  const GlBuffer outs(count * sizeof(GpuRayScan), nullptr);
  WalkingScan out;
  const uint64_t room = batching.first_room ? batching.first_room : 8 * static_cast<uint64_t>(count);
  out.candidates = scan_pass(b, cube, in, p, room, count, [&] {
    set_walk_uniforms(p, cube.n, cap);
    b.positions->bind(CUBE_SCAN_POSITIONS_BINDING);
    outs.bind(CUBE_WALK_COUNTS_BINDING);
    b.blocks->bind(CUBE_SCAN_BLOCKS_BINDING);
    glUniform1i(p.uniform("blocks_per_row"), b.blocks_per_row);
    glUniform1ui(p.uniform("ray_count"), static_cast<GLuint>(count));
    glUniform1d(p.uniform("skip_radius"), cube.near_distance);
    glUniform1ui(p.uniform("opaque_at"), opaque_at);
    glUniform1ui(p.uniform("loop_budget"), batching.loop_budget);
    glUniform1ui(p.uniform("one"), 1u);
    glUniform3d(p.uniform("centre"), cube.centre.x, cube.centre.y, cube.centre.z);
    glUniform1d(p.uniform("on_triangle_texels"), ON_TRIANGLE_TEXELS);
    glUniform1d(p.uniform("tolerance_texels"), in.tolerance_texels);
  });
  out.rays = outs.read<GpuRayScan>(count);
  return out;
}

// A walking scan's results into out[first ...]; the rays past the loop budget into `over`.
void unpack_walking(WalkingScan found, size_t first, const std::vector<uint32_t>& face_first, CandidateScan* out,
                    std::vector<size_t>* over) {
  for (size_t k = 0; k < found.rays.size(); ++k) {
    const GpuRayScan& r = found.rays[k];
    if (!(r.flags & SCAN_LOOPS_RAN) || !(r.flags & (SCAN_ENDED | SCAN_STOPPED | SCAN_OVER_BUDGET))) {
      throw RuntimeFailure("GPU candidate scan: the GL ended ray " + std::to_string(first + k) +
                           "'s scan early (a loop limit?)");
    }
    CandidateScan& c = out[first + k];
    if (r.flags & SCAN_OVER_BUDGET) {
      over->push_back(first + k);
      continue;
    }
    c.texels = r.texels;
    c.aborted = (r.flags & SCAN_CAPPED) != 0;
    c.stopped = (r.flags & SCAN_STOPPED) != 0;
    if (c.stopped) c.last_l1 = r.last_l1;
  }
  std::sort(found.candidates.begin(), found.candidates.end(), [](const GpuCandidate& x, const GpuCandidate& y) {
    if (x.ray != y.ray) return x.ray < y.ray;
    return x.texel != y.texel ? x.texel < y.texel : x.fragment < y.fragment;
  });
  for (const GpuCandidate& g : found.candidates) {
    if (found.rays[g.ray].flags & SCAN_OVER_BUDGET) continue;
    out[first + g.ray].candidates.push_back(unpacked_candidate(g, g.texel, face_first));
  }
}

}  // namespace

std::vector<CandidateScan> GlCandidateScan::scan(const std::vector<SearchRay>& rays, const SearchOptions& options,
                                                 const ScanBatching& batching,
                                                 const std::vector<ScanStop>& stops) const {
  if (options.layers != SearchLayers::all) {
    throw InputError("GPU candidate scan: the nearest layer (Z-buffer searches) is scanned on the CPU only");
  }
  if (!stops.empty() && stops.size() != rays.size()) {
    throw InputError("GPU candidate scan: " + std::to_string(stops.size()) + " stop hints for " +
                     std::to_string(rays.size()) + " rays");
  }
  const Buffers& b = *buffers_;
  const CubeABuffer& cube = ctx_->cube();
  const uint32_t cap = walk_cap(cube.n, options.max_texels);
  std::vector<WalkRay> walk_rays(rays.size());
  std::vector<GpuScanRay> packed(rays.size());
  for (size_t k = 0; k < rays.size(); ++k) {
    const SearchRay& q = rays[k];
    walk_rays[k] = {q.w, q.d, q.l_max, cube.near_distance};
    check_walk_ray(walk_rays[k], k);
    packed[k] = {{q.w.x, q.w.y, q.w.z, q.l_max},
                 {q.d.x, q.d.y, q.d.z, q.self},
                 {q.object, NO_ROW, stops.empty() ? 0u : static_cast<uint32_t>(stops[k]), 0},
                 {q.self_tolerance, 0.0}};
  }
  static_assert(static_cast<uint32_t>(ScanStop::crossing) == 1 && static_cast<uint32_t>(ScanStop::shadow) == 2,
                "cube_scan_walks.comp's STOP_CROSSING and STOP_SHADOW");
  std::vector<uint32_t> objects = b.objects;
  const uint32_t rows_at = static_cast<uint32_t>(objects.size());
  uint32_t row_words = 0;
  add_restriction_rows(*ctx_, rays, &packed, &objects, &row_words);
  const uint32_t opaque_at = static_cast<uint32_t>(objects.size());
  objects.insert(objects.end(), b.opaque.begin(), b.opaque.end());
  check_block("the objects, their restriction rows and the opaque triangles", objects.size() * sizeof(uint32_t));
  const GlBuffer object_buffer(objects.size() * sizeof(uint32_t), objects.data());
  std::vector<CandidateScan> out(rays.size());
  // An invocation a ray first; the rays past its loop budget walked, then scanned a texel an
  // invocation, whole.
  std::vector<size_t> walked;
  for (size_t chunk = 0; chunk < rays.size(); chunk += WALK_RAY_CHUNK) {
    const size_t count = std::min(WALK_RAY_CHUNK, rays.size() - chunk);
    const GlBuffer ray_buffer(count * sizeof(GpuScanRay), packed.data() + chunk);
    const BatchInputs in{&ray_buffer, &object_buffer,           rows_at,
                         row_words,   options.tolerance_texels, options.refine == SearchRefine::mesh};
    unpack_walking(scan_walking(b, cube, in, cap, count, opaque_at, batching), chunk, b.face_first, out.data(),
                   &walked);
  }
  if (walked.empty()) return out;
  std::vector<WalkRay> walk_left(walked.size());
  std::vector<GpuScanRay> packed_left(walked.size());
  for (size_t k = 0; k < walked.size(); ++k) {
    walk_left[k] = walk_rays[walked[k]];
    packed_left[k] = packed[walked[k]];
  }
  std::vector<CandidateScan> left(walked.size());
  b.walks.walk_batches(
      walk_left, cube.n, options.max_texels,
      [&](const GlCubeWalks::Batch& batch) {
        for (size_t k = batch.first; k < batch.end; ++k) {
          left[batch.chunk + k].texels = (*batch.counts)[4 * k];
          left[batch.chunk + k].aborted = ((*batch.counts)[4 * k + 1] & 1u) != 0;
        }
        if (batch.texel_count == 0) return;
        const GlBuffer ray_buffer((batch.end - batch.first) * sizeof(GpuScanRay),
                                  packed_left.data() + batch.chunk + batch.first);
        const BatchInputs in{&ray_buffer, &object_buffer,           rows_at,
                             row_words,   options.tolerance_texels, options.refine == SearchRefine::mesh};
        unpack_candidates(scan_batch(b, cube, in, batch, batching.first_room ? batching.first_room : batch.texel_count),
                          batch, b.face_first, left.data());
      },
      batching.batch_bytes);
  for (size_t k = 0; k < walked.size(); ++k) out[walked[k]] = std::move(left[k]);
  return out;
}

std::vector<SearchRay> scene_search_rays(const SearchContext& ctx, size_t max_triangles, const SearchOptions& options,
                                         std::vector<int>* lights) {
  const SceneData& scene = ctx.scene();
  const TriangleSoup& soup = *scene.triangles;
  std::vector<SearchRay> rays;
  const auto add = [&](const SearchRay& q, int light) {
    rays.push_back(q);
    if (lights) lights->push_back(light);
  };
  for_spread_triangles(soup, max_triangles, [&](size_t t, const glm::dvec3& x, const glm::dvec3& normal) {
    const glm::dvec3 view = x - scene.camera.position;
    const double view_len = glm::length(view);
    if (!(view_len > 0.0) || !std::isfinite(view_len)) return;
    const glm::dvec3 dir = view / view_len;
    add(reflection_ray(ctx, x, glm::reflect(dir, normal), options), -1);
    for (size_t k = 0; k < scene.lights.size(); ++k) {
      SearchRay q;
      if (shadow_ray(ctx, x, scene.lights[k].position, options, &q)) add(q, static_cast<int>(k));
    }
    if (scene.materials[soup.material_id[t]].transmit > 0.0) {
      add(refraction_exit_ray(ctx, x, dir, soup.object_id[t], options), -1);
    }
  });
  return rays;
}

namespace {

// The first candidate of x and y not identical (bits), and whether every one is at the same
// place with the same verdicts and values within rounding.
size_t first_not_identical(const std::vector<ScanCandidate>& x, const std::vector<ScanCandidate>& y, bool* rounding) {
  size_t k = 0;
  *rounding = x.size() == y.size();
  for (size_t c = 0; c < std::min(x.size(), y.size()); ++c) {
    const ScanCandidate &p = x[c], &q = y[c];
    const bool place = p.same_place(q);
    if (k == c && place && same_bits(p.l, q.l) && same_bits(p.outside, q.outside) && same_bits(p.l1, q.l1) &&
        same_bits(p.before_l1, q.before_l1))
      ++k;
    *rounding = *rounding && place && within_rounding(p.l, q.l) && within_rounding(p.outside, q.outside) &&
                within_rounding(p.l1, q.l1) && within_rounding(p.before_l1, q.before_l1);
  }
  return k;
}

void put_candidate(std::ostringstream& what, const std::vector<ScanCandidate>& v, size_t k) {
  if (k >= v.size()) {
    what << "none";
    return;
  }
  const ScanCandidate& c = v[k];
  what << "texel " << c.texel << " face " << c.face << " fragment " << c.fragment;
  if (c.tested)
    what << " l " << c.l << " outside " << c.outside << (c.valid ? " valid" : "") << (c.exact ? " exact" : "");
}

}  // namespace

CandidateComparison compare_candidate_scans(const std::vector<CandidateScan>& a, const std::vector<CandidateScan>& b) {
  CandidateComparison c;
  c.rays = a.size();
  for (size_t r = 0; r < a.size(); ++r) {
    c.candidates += a[r].candidates.size();
    const bool walks_alike = r < b.size() && a[r].texels == b[r].texels && a[r].aborted == b[r].aborted &&
                             a[r].stopped == b[r].stopped && same_bits(a[r].last_l1, b[r].last_l1);
    bool rounding = false;
    const size_t k = walks_alike ? first_not_identical(a[r].candidates, b[r].candidates, &rounding) : 0;
    if (walks_alike && rounding && k == a[r].candidates.size()) {
      ++c.identical;
      continue;
    }
    rounding = walks_alike && rounding;
    std::ostringstream what;
    if (!count_not_identical(r, rounding, r < b.size(), &c, &what)) continue;
    what << a[r].candidates.size() << " candidates in " << a[r].texels << " texels"
         << (a[r].aborted ? " (aborted)" : "") << " against " << b[r].candidates.size() << " in " << b[r].texels
         << (b[r].aborted ? " (aborted)" : "");
    if (k < a[r].candidates.size() || k < b[r].candidates.size()) {
      what << "; candidate " << k << ": ";
      put_candidate(what, a[r].candidates, k);
      what << " against ";
      put_candidate(what, b[r].candidates, k);
    }
    c.example = what.str();
  }
  count_extra_rays(a.size(), b.size(), &c);
  return c;
}

}  // namespace abcube
