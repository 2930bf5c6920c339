// The searches' candidates on the GPU: the z-interval test of thesis 7.5 over the cube
// A-buffer's lists, along the texels each ray's walk crosses, with the object restriction and
// the own-surface test, then each candidate's crossing test with its MESH REFINEMENT:
// scan_candidates (cpu_core/search/search.hpp), STOP HINTS included, run by GL compute
// passes. An invocation a ray walks and scans its texels' lists as it goes
// (shaders/cube_scan_walks.comp); a ray past what one invocation may loop is walked by
// GlCubeWalks and its texels scanned an invocation a texel (shaders/cube_scan.comp). Then an
// invocation a candidate runs its crossing test (shaders/cube_refine.comp, mesh_refine.glsl).
// Their expressions are the CPU's in double precision, so that a GL whose doubles round as
// IEEE 754 says finds the CPU's candidates and crossings exactly: compare_candidate_scans says
// where they differ.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "gl/gl_cube_walks.hpp"
#include "search/search.hpp"

namespace abcube {

// What one invocation of the scan that walks may loop (cube_scan_walks.comp counts its
// loops against it): under llvmpipe's 65535.
constexpr uint32_t GPU_SCAN_LOOP_BUDGET = 60000;

// What a scan holds a ray beside the upload, on the GPU and the host, with room for eight
// candidates a ray (a batch whose rays find more takes more for them): the ray as sent, its
// walk's summary, the candidates' room and their copies read back, and its CandidateScan.
constexpr uint64_t GPU_SCAN_RAY_BYTES = 3072;

// How GlCandidateScan::scan cuts its work: a pass's first try has room for first_room
// candidates (0: eight a ray in the scan that walks, one a texel walked in the other), and
// runs again with room for all it found when they are more; the walks left on the GPU go in
// batches of at most batch_bytes of texels; a ray whose scan would count more than
// loop_budget loops is walked first (0: every ray).
struct ScanBatching {
  uint64_t batch_bytes = WALK_BATCH_BYTES;
  uint64_t first_room = 0;
  uint32_t loop_budget = GPU_SCAN_LOOP_BUDGET;
};

// The lists and the triangles' planes, objects, vertices and edge neighbours of one
// SearchContext, uploaded once, and the compiled passes, on the GL context current when it
// was made (GL 4.5 core with storage buffer binding CUBE_SCAN_POSITIONS_BINDING), which must
// stay current for its life. The context must outlive it.
class GlCandidateScan {
 public:
  // Throws RuntimeFailure when the GL cannot hold the lists, the fragments, or the triangles'
  // planes, vertices or neighbours in one storage block each, or a list is longer than
  // GPU_SCAN_MAX_LIST.
  explicit GlCandidateScan(const SearchContext& ctx);
  // What the constructor uploads and keeps, on the GPU and the host: the lists' offsets and
  // fragments, the triangles' planes, vertices, neighbours, objects and opaque bits.
  static uint64_t upload_bytes(const SearchContext& ctx);
  ~GlCandidateScan();
  GlCandidateScan(const GlCandidateScan&) = delete;
  GlCandidateScan& operator=(const GlCandidateScan&) = delete;

  // Every ray's scan_candidates(ctx, ray, options, stops[ray]) (`stops` empty: none). Throws
  // InputError for the nearest layer (options.layers: the Z-buffer's choice is the CPU's
  // alone), for a walk cap above GPU_WALK_MAX_TEXELS, on a ray GlCubeWalks refuses and on
  // stops not one a ray; RuntimeFailure when the objects' restriction rows or one pass's
  // candidates exceed a storage block, or the GL ended a scan early.
  // `batching` sets how the work is cut, not what it finds.
  std::vector<CandidateScan> scan(const std::vector<SearchRay>& rays, const SearchOptions& options = {},
                                  const ScanBatching& batching = {}, const std::vector<ScanStop>& stops = {}) const;

  struct Buffers;

 private:
  const SearchContext* ctx_;
  std::unique_ptr<Buffers> buffers_;
};

// The longest list the GPU's scan reads: an invocation reads one texel's list, and Mesa's
// llvmpipe ends an invocation's loops, silently, after 65535 passes in all.
constexpr uint32_t GPU_SCAN_MAX_LIST = 60000;

// A scene's search rays as the searches make them (reflection_ray, shadow_ray,
// refraction_exit_ray), for the cross-checks and benchmarks: from the centroids of up to
// `max_triangles` triangles spread over the scene, the reflection of the ray from the camera
// about the triangle's plane, the segment to each light, and, on a triangle whose material
// transmits, the camera's ray carried on into its object (a refraction exit). Degenerate
// triangles give none.
// `lights` (optional): per ray, the index of the light a shadow segment goes to, else -1.
std::vector<SearchRay> scene_search_rays(const SearchContext& ctx, size_t max_triangles,
                                         const SearchOptions& options = {}, std::vector<int>* lights = nullptr);

// How two sets of scans of the same rays agree, ray by ray, in three classes:
// - identical: the same candidates in the same order with the same verdicts, their l and
//   outside the same bits, the same texels walked and cap;
// - within rounding: the same but for an l or an outside within WALK_ROUNDING_REL of the
//   other's (what a GL's double division and square root may move);
// - differing: anything else.
// `example` gives the first ray not identical, in words.
struct CandidateComparison {
  size_t rays = 0, identical = 0, within_rounding = 0, differing = 0;
  uint64_t candidates = 0;  // in the first set
  std::string example;
};
CandidateComparison compare_candidate_scans(const std::vector<CandidateScan>& a, const std::vector<CandidateScan>& b);

}  // namespace abcube
