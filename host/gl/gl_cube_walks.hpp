// The cube walk on the GPU: CubeWalk's plain walk (cpu_core/search/cube_walk.hpp) run by a
// GL compute shader (shaders/cube_walk.glsl), an invocation a ray, the first brick of the
// searches on the GPU. Its expressions are the CPU's in double precision, operation for
// operation, so that a GL whose doubles round as IEEE 754 says walks the same texels with
// the same intervals bit for bit: compare_walks says where they differ.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene_data.hpp"
#include "search/cube_walk.hpp"

namespace abcube {

class GlBuffer;
class GlProgram;

// Rays a chunk of a GPU walk: their storage blocks stay well under the 128 MiB a GL must offer.
constexpr size_t WALK_RAY_CHUNK = size_t{1} << 18;
// The texels a batch of GPU walks holds at most, in bytes: 2 Mi texels.
constexpr uint64_t WALK_BATCH_BYTES = uint64_t{64} << 20;

// A ray to walk: CubeWalk's arguments (w relative to the centre, d unit).
struct WalkRay {
  glm::dvec3 w{0.0}, d{0.0, 0.0, 1.0};
  double l_max = std::numeric_limits<double>::infinity();
  double skip_radius = 0.0;
};

// A ray's walk: its texels in order, and whether the cap stopped it.
struct RayWalk {
  std::vector<WalkTexel> texels;
  bool aborted = false;
};

// The compiled passes, on the GL context current when it was made (GL 4.5 core with storage
// buffer binding CUBE_WALK_OFFSETS_BINDING), which must stay current for its life: a count
// pass walks every ray for its length, a fill pass walks them again to write their texels,
// in batches whose texels take at most 64 MiB on the GPU.
class GlCubeWalks {
 public:
  GlCubeWalks();
  ~GlCubeWalks();
  GlCubeWalks(const GlCubeWalks&) = delete;
  GlCubeWalks& operator=(const GlCubeWalks&) = delete;

  // Every ray's walk on an n x n map, each capped at max_texels (0: CubeWalk's default).
  // Throws InputError on a ray CubeWalk refuses (d not unit, w not finite), on n < 1, and
  // on a cap above GPU_WALK_MAX_TEXELS.
  std::vector<RayWalk> walk(const std::vector<WalkRay>& rays, int n, uint32_t max_texels = 0) const;

  // The walks left on the GPU, for a pass that reads them there (gl_cube_scan.hpp): the rays
  // go in chunks of WALK_RAY_CHUNK, and each chunk's fill pass in batches of rays whose texels
  // take at most batch_bytes (one ray's at least); visit() is called
  // once a batch, its texels bound at CUBE_WALK_TEXELS_BINDING (cube_walk.glsl's
  // WalkTexelOut) and its offsets at CUBE_WALK_OFFSETS_BINDING. Every walk of a batch has
  // been checked ended by both passes. The same refusals as walk().
  struct Batch {
    size_t chunk = 0;           // the chunk's first ray
    size_t first = 0, end = 0;  // the batch's rays, chunk + [first, end)
    uint64_t texel_count = 0;
    std::vector<uint32_t> offsets;                  // ray chunk + first + k's first texel in the batch
    const std::vector<uint32_t>* counts = nullptr;  // per chunk ray: (count, flags, -, -); flag 1: the cap stopped it
    const GlBuffer* texels = nullptr;
    const GlBuffer* offset_buffer = nullptr;
  };
  void walk_batches(const std::vector<WalkRay>& rays, int n, uint32_t max_texels,
                    const std::function<void(const Batch&)>& visit, uint64_t batch_bytes = WALK_BATCH_BYTES) const;

  struct Program;

 private:
  std::unique_ptr<Program> program_;
};

// The largest cap a GPU walk takes. Mesa's llvmpipe ends an invocation's loops, silently,
// after 65535 iterations in all, and it counts more than one a texel (the compiler turns a
// function's early returns into loops of their own): walks of 24000 texels were cut short
// there and walks of 16000 were not. A walk cut short is refused (RuntimeFailure), never
// returned short. CubeWalk's default cap, 16 n + 64, is within this bound up to n = 996.
constexpr uint32_t GPU_WALK_MAX_TEXELS = 16000;
// The cap of a GPU walk on an n x n map asked for max_texels (0: CubeWalk's default); InputError
// on n < 1 and on a cap above GPU_WALK_MAX_TEXELS.
uint32_t walk_cap(int n, uint32_t max_texels);
// InputError on a ray CubeWalk refuses (d not unit, w not finite), named by its index.
void check_walk_ray(const WalkRay& r, size_t index);
// Sets cube_walk.glsl's uniforms of program p (made current) for walks of an n x n map, capped.
void set_walk_uniforms(const GlProgram& p, int n, uint32_t cap);
// Whether a walk of an n x n map at CubeWalk's default cap runs on the GPU.
inline bool gpu_walks_at(int n) { return n >= 1 && CubeWalk::default_cap(n) <= GPU_WALK_MAX_TEXELS; }

// A scene's search rays, for the walks' cross-checks and benchmarks: from the centroids of up
// to `max_triangles` triangles spread over the scene (relative to `centre`), the segment to
// each light (a shadow ray's walk) and the ray reflecting the view from the centre about the
// triangle's plane (a reflection ray's). Degenerate triangles give none.
std::vector<WalkRay> scene_walk_rays(const SceneData& scene, const glm::dvec3& centre, size_t max_triangles);

// Calls visit(triangle, centroid, unit normal) for up to `max_triangles` of the soup's
// triangles, spread evenly over it, skipping degenerate ones.
void for_spread_triangles(const TriangleSoup& soup, size_t max_triangles,
                          const std::function<void(size_t, const glm::dvec3&, const glm::dvec3&)>& visit);

// The same rays walked by CubeWalk on the CPU.
std::vector<RayWalk> cpu_cube_walks(const std::vector<WalkRay>& rays, int n, uint32_t max_texels = 0);

// How two sets of walks of the same rays agree, ray by ray, in three classes:
// - identical: the same texels in the same order (face, i, j, after_gap), both ends of every
//   interval the same bits, the same cap;
// - within rounding: the same texels and cap, every end within WALK_ROUNDING_REL of the
//   other's: what a GL whose double divisions and square roots round otherwise than IEEE 754
//   may move (GLSL promises them only single precision);
// - differing: anything else (another texel, another count, the cap).
// `example` gives the first ray not identical, in words.
constexpr double WALK_ROUNDING_REL = 1e-12;
inline bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
// Within WALK_ROUNDING_REL of each other (the same infinity included).
inline bool within_rounding(double a, double b) {
  return a == b || std::fabs(a - b) <= WALK_ROUNDING_REL * std::max(std::fabs(a), std::fabs(b));
}
struct WalkComparison {
  size_t rays = 0, identical = 0, within_rounding = 0, differing = 0;
  uint64_t texels = 0;  // in the first set
  std::string example;
};
WalkComparison compare_walks(const std::vector<RayWalk>& a, const std::vector<RayWalk>& b);

// The rays a second set of `b` results has beyond the first's `a`, counted differing (and
// named, where no ray was yet).
template <class Comparison>
void count_extra_rays(size_t a, size_t b, Comparison* c) {
  if (b <= a) return;
  c->rays = b;
  c->differing += b - a;
  if (c->example.empty()) c->example = "the second set has " + std::to_string(b - a) + " rays more";
}

// Counts ray `r`, not identical, in its class. For the first such ray it starts the example in
// `what` ("ray r (within rounding): ") and returns true: the caller finishes it and stores it.
// It returns false when an example was already given, or when the second set lacks the ray
// (the example is then whole).
template <class Comparison>
bool count_not_identical(size_t r, bool rounding, bool in_second, Comparison* c, std::ostringstream* what) {
  ++(rounding ? c->within_rounding : c->differing);
  if (!c->example.empty()) return false;
  what->precision(17);
  *what << "ray " << r << (rounding ? " (within rounding): " : ": ");
  if (in_second) return true;
  c->example = what->str() + "missing from the second set";
  return false;
}

}  // namespace abcube
