// The A-buffer (thesis 5.2; Carpenter 1984): per pixel, the list of every triangle's
// fragment, front AND back faces, sorted front to back, for the six faces of a cube around a
// centre (the environment map) or for the camera view. STORAGE: prefix-sum offsets and one
// flat fragment array, built in count, budget-check and fill passes over row bands, so the
// bytes are identical for any number of threads. ORDER: by zmin, then triangle and facing (a
// total order). MERGE (thesis 5.2.1): same object, material and facing, overlapping z and
// disjoint masks, plus OUR ADDITION (normals within MERGE_MIN_NORMAL_COS, so a crease keeps
// both planes). CAP: max_layers. docs/design/abuffer-lists.md has the whole argument.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "base/normal_encoding.hpp"
#include "io/image.hpp"
#include "raster/raster.hpp"
#include "base/samples.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

// cos(20 degrees): fragments whose normals differ more do not merge (a crease).
constexpr double MERGE_MIN_NORMAL_COS = 0.93969262078590838;

// 20 bytes. zmin/zmax are rounded outward to float (zmin down, zmax up), so they still
// bracket the exact distances.
struct Fragment {
  static constexpr uint32_t BACK_FACE_BIT = 0x80000000u;
  float zmin = 0, zmax = 0;          // Euclidean distance from the centre over the covered part
  CoverageMask mask = 0;             // bit k = sample k (samples.hpp)
  uint32_t triangle_and_facing = 0;  // triangle index | BACK_FACE_BIT for a back face
  uint32_t normal = 0;               // encode_octahedral of the interpolated shading normal

  uint32_t triangle() const { return triangle_and_facing & ~BACK_FACE_BIT; }
  bool back_face() const { return (triangle_and_facing & BACK_FACE_BIT) != 0; }
  glm::dvec3 shading_normal() const { return decode_octahedral(normal); }
};
static_assert(sizeof(Fragment) == 20, "Fragment layout: 2 floats + 3 words");

// A pixel's list, front to back.
struct FragmentList {
  const Fragment* first = nullptr;
  const Fragment* last = nullptr;  // one past the end
  const Fragment* begin() const { return first; }
  const Fragment* end() const { return last; }
  size_t size() const { return static_cast<size_t>(last - first); }
  bool empty() const { return first == last; }
  const Fragment& operator[](size_t i) const { return first[i]; }
};

struct ABuffer {
  RasterView view;
  std::vector<uint32_t> offsets;  // view.pixel_count() + 1 entries
  std::vector<Fragment> fragments;

  int width() const { return view.width; }
  int height() const { return view.height; }
  FragmentList list(int x, int y) const {
    const size_t p = static_cast<size_t>(y) * static_cast<size_t>(view.width) + static_cast<size_t>(x);
    return {fragments.data() + offsets[p], fragments.data() + offsets[p + 1]};
  }
};

// Six faces in cube_map.hpp order around one centre.
struct CubeABuffer {
  int n = 0;
  glm::dvec3 centre{0.0};
  double near_distance = 0;
  std::array<ABuffer, 6> faces;
};

struct ABufferOptions {
  int threads = 0;           // 0 = std::thread::hardware_concurrency()
  double near_distance = 0;  // 0 = default_near_distance(farthest vertex from the centre)
  uint32_t max_layers = 0;   // 0 = keep every layer
  // The render's memory budget (--max-memory), 0 = the memory available
  // (memory_budget_bytes, scene_load.hpp); the A-buffer may take what `reserved_bytes`, the
  // rest of the render's estimate (estimate_render_bytes, an A-buffer built before), leaves.
  uint64_t max_memory_bytes = 0;
  uint64_t reserved_bytes = 0;
  bool merge = true;  // false keeps one fragment per triangle and pixel (tests)
};

struct ABufferStats {
  uint64_t fragments = 0;                    // stored, after merging and the cap
  uint64_t raw_fragments = 0;                // triangle-pixel pairs before merging
  std::vector<uint64_t> fragments_per_view;  // per face (or the one camera view)
  uint64_t max_list_length = 0;
  uint64_t dropped_by_cap = 0;
  uint64_t bytes_per_fragment = sizeof(Fragment);
  uint64_t bytes_total = 0;  // fragments and offsets as stored (after merging)
  // The budget check's figure: the raw fragments, the per-pixel index and the triangle bins.
  // It is the peak: the fragment arrays keep the raw count's capacity after merging.
  uint64_t estimated_bytes = 0;
  uint64_t budget_bytes = 0;
  uint64_t triangle_views = 0;        // (triangle, view) pairs rasterised
  uint64_t triangles_clipped = 0;     // (triangle, view) pairs cut by the near plane
  uint64_t triangles_culled = 0;      // triangles no view sees (behind near / outside)
  uint64_t triangles_degenerate = 0;  // non-finite or zero-area
  uint64_t triangles_edge_on = 0;     // plane through the centre
  double near_distance = 0;
  double count_ms = 0, fill_ms = 0, total_ms = 0;
  int threads = 0;
};

// What a cube build does before it rasterises, shared with the GPU build (host/gl/gl_abuffer.hpp):
// per triangle, the faces that may hold its samples (cube_faces_of; all six for a degenerate
// or edge-on triangle, so that every face counts it), one byte a triangle.
std::vector<uint8_t> triangle_cube_faces(const TriangleSoup& soup, const glm::dvec3& centre, int threads);
// The A-buffer's estimate `need` with the rest of the render's (options.reserved_bytes)
// against `budget`; throws InputError "WHAT needs N MiB (DETAIL) beside R MiB for the rest of
// the render, above ..." when over it.
void check_abuffer_budget(const char* what, uint64_t need, const std::string& detail, const ABufferOptions& options,
                          uint64_t budget);
// A pixel's raw list (`count` fragments from `list`, in any order) finished as every build
// finishes it: sorted front to back, merged (options.merge: MERGE) and cut to
// options.max_layers. Returns the kept count (the kept fragments first in `list`), and adds
// to *dropped the fragments the cap left out.
uint32_t finish_fragment_list(const TriangleSoup& soup, const ABufferOptions& options, Fragment* list, uint32_t count,
                              uint64_t* dropped);
// A cube build's six face views around `centre` at `n` (cube_map.hpp's order), after its
// arguments are checked (InputError naming `what`: n < 1, a centre not finite) and its near
// distance chosen (abuffer_near_distance).
std::vector<RasterView> cube_build_views(const char* what, const SceneData& scene, const glm::dvec3& centre, int n,
                                         const ABufferOptions& options);
// A cube build's result from its six faces' lists (cube_build_views' order).
CubeABuffer cube_of_faces(int n, const glm::dvec3& centre, double near_distance, std::vector<ABuffer> faces);
// The near distance a build around `centre` uses: options.near_distance, or when 0 the
// default for the farthest vertex. Throws InputError for a bad option.
double abuffer_near_distance(const SceneData& scene, const glm::dvec3& centre, const ABufferOptions& options);

// The cube A-buffer of `scene` around `centre` (the environment map), n x n
// per face. Throws InputError for n < 1, a bad option, or when the estimate exceeds the
// budget: "cube A-buffer needs N MiB (F fragments at 20 bytes) beside R MiB for the rest of
// the render, above --max-memory M MiB" (or "the M MiB of memory available").
CubeABuffer build_cube_abuffer(const SceneData& scene, const glm::dvec3& centre, int n,
                               const ABufferOptions& options = {}, ABufferStats* stats = nullptr);

// The camera view's A-buffer (scene.camera, its width x height), same rules.
ABuffer build_camera_abuffer(const SceneData& scene, const ABufferOptions& options = {}, ABufferStats* stats = nullptr);

// The four samples nearest the pixel centre (columns 3-4 of rows 1-2): there is no sample
// at (0.5, 0.5), so "the texel centre is covered" means "one of these is".
constexpr CoverageMask CENTRE_SAMPLES =
    (1u << sample_index(3, 1)) | (1u << sample_index(4, 1)) | (1u << sample_index(3, 2)) | (1u << sample_index(4, 2));

// The front-most fragment (in list order) covering a centre sample, or nullptr.
const Fragment* centre_fragment(const ABuffer& buffer, int x, int y);

// Per texel, what a one-layer distance prepass would hold at the texel centre: the
// distance from the centre along the texel-centre direction to the plane of the nearest
// (smallest such distance) fragment covering a centre sample, and its object id. Texels
// without one hold +infinity and UINT32_MAX. Also the Z-buffered map's layer (Patow 1995).
// Surfaces at the same distance: the one whose triangle holds the texel centre itself
// (coplanar triangles meeting at an edge between the centre samples), else THE TIE RULE
// (scene/tie_rule.hpp) picks, and `tied` marks
// the texel (1) when another object's fragment over one of the same centre samples was at
// that distance (coincident surfaces; two surfaces meeting at an edge cover disjoint samples).
struct NearestLayer {
  CubeImage distance;  // 1 channel
  CubeIds object;
  CubeIds tied;  // 1 where the tie rule decided between objects, else 0
};
NearestLayer nearest_layer(const CubeABuffer& cube, const TriangleSoup& triangles);

// The world point a fragment of pixel (x, y) stands for: its triangle's plane along the
// direction through the centroid of its covered samples.
glm::dvec3 fragment_point(const ABuffer& buffer, const TriangleSoup& triangles, const Fragment& f, int x, int y);

}  // namespace abcube
