// The searches in the A-buffered cube map (thesis 7.4, 7.5, 8.3, 9.3.4): reflection,
// refraction exit and shadow rays answered from ONE cube A-buffer (abuffer.hpp) centred on
// C, by walking the texels of the ray's projection (cube_walk.hpp) in order of increasing
// ray parameter l and testing the fragments whose depth range meets the ray's. The rules are
// named in capitals (CANDIDATES, HIERARCHICAL SKIP, MODE crossing, MESH REFINEMENT, MODE
// thesis, SELF-HITS, THE SIDE STRUCTURE, THE CENTRE, SHADOWS, REFRACTION);
// docs/design/search.md has the whole argument of each. Every search is a pure function of
// its inputs (thread safe); stats are per caller.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "raster/abuffer.hpp"
#include "raster/cube_map.hpp"
#include "reference/bvh.hpp"
#include "scene/scene_data.hpp"
#include "material/media.hpp"

namespace abcube {

// Per triangle, the triangle across each edge k (vertices k, k+1): same object, the same
// two vertex positions bit for bit; SearchContext::NO_NEIGHBOUR on a border or a
// non-manifold edge. Depends on the triangles only: one per scene.
// Three entries a triangle in one array (what the edge pairing gives, converted in place).
struct MeshNeighbours {
  std::vector<uint32_t> across;  // 3 t + k: across edge k of triangle t
  const uint32_t* operator[](size_t triangle) const { return across.data() + 3 * triangle; }
  size_t size() const { return across.size() / 3; }
};
MeshNeighbours build_mesh_neighbours(const TriangleSoup& soup);

enum class SearchMode { crossing, thesis };
enum class SearchLayers { all, nearest };  // A-buffer (thesis 7.5) or Z-buffer (Patow 1995)
enum class SearchRefine { mesh, plane };   // crossing mode: MESH REFINEMENT on or off
const char* search_mode_name(SearchMode m);
bool parse_search_mode(const std::string& s, SearchMode* out);  // "crossing" | "thesis"
const char* search_refine_name(SearchRefine r);
bool parse_search_refine(const std::string& s, SearchRefine* out);  // "mesh" | "plane"

// Texels the crossing mode walks past its first accepted candidate, and the thesis mode
// past its first candidate under theta_max.
constexpr int CROSSING_WINDOW_TEXELS = 2;
constexpr int THESIS_WINDOW_TEXELS = 2;
// A refined point this close to its triangle (in texels) is on it: rounding, not tolerance.
constexpr double ON_TRIANGLE_TEXELS = 1e-6;
// Default self offsets per mode, in texels at W (SELF-HITS, docs/design/search.md).
constexpr double SELF_OFFSET_CROSSING_TEXELS = 1e-3;
constexpr double SELF_OFFSET_THESIS_TEXELS = 0.5;
// MESH REFINEMENT: the most steps of its straight walk, and the most triangles its flood
// visits before it gives up (unknown). A flood must see every triangle near the ray to say
// it passes by: where a model's triangles are smaller than a texel (a scanned or subdivided
// mesh at a modest N), 32 left such rays to the plane tolerance, which took the extension of
// a small triangle's plane for a crossing (false self-shadows on the Wuson).
constexpr size_t REFINE_MAX_STEPS = 32;
constexpr size_t REFINE_MAX_TRIANGLES = 128;

struct SearchOptions {
  SearchMode mode = SearchMode::crossing;
  SearchLayers layers = SearchLayers::all;
  double theta_max = 0.034906585039886591;   // thesis mode: 2 degrees, in radians
  double tolerance_texels = 1.0;             // crossing mode: largest accepted e
  SearchRefine refine = SearchRefine::mesh;  // MESH REFINEMENT (docs/design/search.md)
  double self_offset_texels = 0;             // W's own surface and points closer; 0 = the mode's default
  uint32_t max_texels = 0;                   // walk cap; 0 = CubeWalk's default
  bool side_structure = true;                // THE SIDE STRUCTURE answers what the map cannot hold
  bool hierarchy = true;                     // HIERARCHICAL SKIP (search_scan.hpp); off: the plain walk (same answers)
  bool known_blockers = true;                // KNOWN BLOCKER (shadow_search); off: every segment walked
};

// The self offset `options` gives, in texels at W (its own, or the mode's default).
double self_offset_texels(const SearchOptions& options);

enum class MissReason { none, no_crossing, threshold_rejection, zero_area_surface, aborted };
const char* miss_reason_name(MissReason r);

// The geometry a search needs, prepared once per cube map: per triangle its plane relative
// to the centre, and the triangles the map cannot hold (THE SIDE STRUCTURE).
// The scene and cube must outlive it.
class SearchContext {
 public:
  // `neighbours` (optional): the scene's edge adjacency, built once per scene and shared
  // by every map of it (SceneCache); built here when null.
  SearchContext(const SceneData& scene, const CubeABuffer& cube,
                std::shared_ptr<const MeshNeighbours> neighbours = nullptr);
  // The same, the adjacency asked of `neighbours` (null: built here) only once THE SIDE
  // STRUCTURE's tree is built: the two are never being built at once, so the
  // peak holds the scratch of one build only (bench/memory.py measures it).
  using NeighboursSource = std::function<std::shared_ptr<const MeshNeighbours>()>;
  SearchContext(const SceneData& scene, const CubeABuffer& cube, const NeighboursSource& neighbours);

  const SceneData& scene() const { return *scene_; }
  const CubeABuffer& cube() const { return *cube_; }
  // The scene's media (NESTED DIELECTRICS, media.hpp): what an exit search may cross.
  const Media& media() const { return media_; }
  const std::vector<uint32_t>& zero_area_triangles() const { return zero_area_; }
  // THE SIDE STRUCTURE (docs/design/search.md): the non-degenerate triangles the map cannot
  // hold (zero area, or no fragment in any face), ascending, and a BVH over them (null when
  // none).
  const std::vector<uint32_t>& side_triangles() const { return side_bvh_ ? side_bvh_->subset() : no_triangles_; }
  bool has_side_triangles() const { return side_bvh_ != nullptr; }
  // tie_rule.hpp's bound for a side triangle against any (0 when there is none).
  double side_tie_bound_max() const { return side_bvh_ ? side_bvh_->tie_bound_max() : 0.0; }
  // Calls visit(triangle, l) for every side triangle the ray C + w + l d (w relative to the
  // centre, d unit) crosses with 0 < l < l_end (the watertight test of
  // reference/triangle_test.hpp), in order of l, then triangle, until visit returns false.
  template <class Visit>
  void for_each_side_crossing(const glm::dvec3& w, const glm::dvec3& d, double l_end, Visit&& visit) const {
    if (!side_bvh_) return;
    std::vector<TriangleHit> hits;  // Embree's order is its own: sorted, the answers are not
    side_bvh_->for_each_hit(RayQuery(cube_->centre + w, d), l_end, [&](const TriangleHit& h) {
      hits.push_back(h);
      return true;
    });
    std::sort(hits.begin(), hits.end(), [](const TriangleHit& a, const TriangleHit& b) {
      return a.t != b.t ? a.t < b.t : a.triangle < b.triangle;
    });
    for (const TriangleHit& h : hits) {
      if (!visit(h.triangle, h.t)) return;
    }
  }

  // Per-triangle geometry is computed from the soup's float vertices on each call, in
  // double, by the same expressions every time (bit for bit the same answer): storing it
  // would cost more memory a triangle than the soup itself.
  struct Plane {
    glm::dvec3 normal{0.0};  // unit geometric normal, cross(b-a, c-a) direction
    double offset = 0;       // normal . X for X on the plane, X relative to the centre
  };
  // Zero for a degenerate triangle.
  Plane plane(uint32_t triangle) const {
    const glm::dvec3 a = vertex(triangle, 0);
    const glm::dvec3 n = glm::cross(vertex(triangle, 1) - a, vertex(triangle, 2) - a);
    const double len = glm::length(n);
    if (!(len > 0.0 && std::isfinite(len))) return {};
    return {n / len, glm::dot(n / len, a)};
  }
  // What the MESH REFINEMENT tests per triangle, relative to the centre, computed when asked
  // from the soup's float vertices: for the crossing test, plane() with the in-plane inward
  // unit normals of the edges (edge k from vertex k to k+1) and their offsets; for the
  // flood, a bounding sphere (centroid, largest vertex distance). Zero for a degenerate
  // triangle (plane()'s test). Two functions, not one: the flood asks for a sphere far more
  // often than for a crossing, and the edges' three normalisations are the costly part.
  struct EdgePlanes {
    Plane plane;
    std::array<glm::dvec3, 3> edge_normal{};
    std::array<double, 3> edge_offset{};
  };
  EdgePlanes compute_edge_planes(uint32_t triangle) const;
  struct Sphere {
    glm::dvec3 centroid{0.0};
    double radius = 0;
  };
  Sphere compute_bounding_sphere(uint32_t triangle) const;
  // Names this context's triangles in the threads' MEMO (search_internal.hpp), which the
  // refinement asks instead of computing each value again; never reused.
  uint64_t memo_id() const { return memo_id_; }
  // The vertices of a triangle relative to the centre.
  glm::dvec3 vertex(uint32_t triangle, int k) const {
    return glm::dvec3(positions_[3 * static_cast<size_t>(triangle) + static_cast<size_t>(k)]) - cube_->centre;
  }
  // The triangle across edge k (vertices k, k+1) of `triangle`: same object, the same two
  // vertex positions bit for bit; NO_NEIGHBOUR on a border or a non-manifold edge.
  static constexpr uint32_t NO_NEIGHBOUR = 0xffffffffu;
  uint32_t neighbour(uint32_t triangle, int k) const { return (*neighbours_)[triangle][static_cast<size_t>(k)]; }

  // Whether every texel (i', j') of `face` with i' - i of the sign of step_i (or 0) and
  // j' - j of the sign of step_j (or 0) holds an empty list: the rest of a walk on that
  // face from (i, j) then meets no fragment (its indices only move that way).
  bool empty_ahead(int face, int i, int j, int step_i, int step_j) const;

  // BLOCK BOUNDS: per face and block of BOUNDS_BLOCK x BOUNDS_BLOCK texels, the smallest
  // zmin and the largest zmax of its fragments. A texel whose block holds nothing in the
  // ray's distance range [dmin, dmax] is passed without reading its list (no fragment of
  // it could pass the z-interval test): a few hundred kilobytes that stay in cache where
  // the lists do not.
  static constexpr int BOUNDS_BLOCK = 8;
  bool block_empty(int face, int i, int j) const { return block_bounds(face, i, j).x > block_bounds(face, i, j).y; }
  // Given the squares of the ray's distance range.
  bool block_misses2(int face, int i, int j, double dmin2, double dmax2) const {
    const glm::vec2 z = block_bounds(face, i, j);
    return static_cast<double>(z.y) * z.y < dmin2 || static_cast<double>(z.x) * z.x > dmax2;
  }
  // THE Z PYRAMID (HIERARCHICAL SKIP, search_scan.hpp): level 0 is the BLOCK BOUNDS; a node
  // of level k + 1 holds the 2 x 2 nodes of level k under it (the smallest zmin and the
  // largest zmax: (+inf, -inf) when empty), up to one node for the whole face. A node of
  // level k covers the texels of a square BOUNDS_BLOCK << k a side (clipped to the face).
  int pyramid_levels() const { return static_cast<int>(level_width_.size()); }
  // The node of `level` holding texel (i, j): (min zmin, max zmax).
  glm::vec2 node_bounds(int face, int level, int i, int j) const {
    if (level == 0) return block_bounds(face, i, j);
    const size_t k = static_cast<size_t>(level);
    const size_t x = static_cast<size_t>(i / BOUNDS_BLOCK) >> k, y = static_cast<size_t>(j / BOUNDS_BLOCK) >> k;
    return pyramid_[static_cast<size_t>(face)][level_offset_[k] + y * level_width_[k] + x];
  }
  // Bytes of the levels above the block bounds (all six faces), and of the block bounds.
  size_t pyramid_bytes() const;
  size_t block_bounds_bytes() const;

 private:
  const SceneData* scene_;
  const CubeABuffer* cube_;
  Media media_;
  const glm::vec3* positions_;  // the soup's, 3 per triangle
  uint64_t memo_id_;            // memo_id()
  std::vector<uint32_t> zero_area_;
  std::shared_ptr<const Bvh> side_bvh_;  // over the side triangles (the scene's soup, not copied)
  std::vector<uint32_t> no_triangles_;
  std::shared_ptr<const MeshNeighbours> neighbours_;
  // Per face and row j: the smallest and largest column holding a fragment over rows
  // <= j (prefix) and >= j (suffix), and in row j alone (n and -1 when none).
  struct RowBounds {
    std::vector<int> min_row, max_row, min_prefix, max_prefix, min_suffix, max_suffix;
  };
  std::array<RowBounds, 6> occupied_;
  int blocks_per_row_ = 0;
  std::array<std::vector<glm::vec2>, 6> block_z_;  // (min zmin, max zmax); empty: (+inf, -inf)
  // THE Z PYRAMID's levels 1 and up, per face, one after the other: level k at
  // level_offset_[k], level_width_[k] nodes a row (index 0: the block level's width).
  std::array<std::vector<glm::vec2>, 6> pyramid_;
  std::vector<size_t> level_offset_;
  std::vector<size_t> level_width_;
  void build_pyramid();
  void build_side_structure(std::vector<uint8_t> seen);
  glm::vec2 block_bounds(int face, int i, int j) const {
    return block_z_[static_cast<size_t>(face)]
                   [static_cast<size_t>(j / BOUNDS_BLOCK) * static_cast<size_t>(blocks_per_row_) +
                    static_cast<size_t>(i / BOUNDS_BLOCK)];
  }
};

struct SearchResult {
  bool hit = false;
  MissReason miss = MissReason::no_crossing;  // none when hit
  uint32_t triangle = 0;                      // the found fragment's triangle (index into SceneData::triangles)
  uint32_t object_id = 0, material_id = 0;
  bool back_face = false;         // the fragment's facing as seen from the cube centre
  glm::dvec3 point{0.0};          // X', world space
  double distance = 0;            // |X' - W|
  double angle = 0;               // angle between the ray and X' - W (radians; 0 in crossing mode)
  double outside_texels = 0;      // crossing mode: X''s distance from its triangle, in texels
  bool side = false;              // answered by THE SIDE STRUCTURE (texel is then meaningless)
  CubeTexel texel{0, 0, 0};       // where the fragment was found
  uint32_t texels_visited = 0;    // texels the walk stepped on
  uint32_t nodes_skipped = 0;     // pyramid nodes it stepped over (HIERARCHICAL SKIP)
  uint32_t fragments_tested = 0;  // z-interval tests
  uint32_t candidates = 0;        // fragments refined (z overlap, not own surface)
  uint32_t mesh_triangles = 0;    // triangles MESH REFINEMENT tested for a crossing (walks and floods)
};

// No triangle (ShadowResult::opaque_blocker, shadow_search's known blocker).
constexpr uint32_t NO_TRIANGLE = 0xffffffffu;

struct ShadowResult {
  glm::dvec3 transmittance{1.0};  // S_l: product of blocker_transmittance over blockers
  bool blocked = false;           // an opaque blocker stopped the walk
  // The blocker, opaque on its own (blocker_transmittance 0), that stopped the segment;
  // NO_TRIANGLE when none did. What a nearby point's search may take as its known blocker.
  uint32_t opaque_blocker = NO_TRIANGLE;
  bool known_blocker = false;  // answered by the known blocker: the map was not walked
  uint32_t blockers = 0;       // distinct crossings counted
  uint32_t first_blocker = 0;  // triangle of the nearest counted blocker (if blockers > 0)
  bool aborted = false;
  bool zero_area = false;      // the segment meets a zero-area surface and no side structure answered
  uint32_t side_blockers = 0;  // blockers found by THE SIDE STRUCTURE
  uint32_t texels_visited = 0;
  uint32_t nodes_skipped = 0;
  uint32_t fragments_tested = 0;
  uint32_t candidates = 0;
  uint32_t mesh_triangles = 0;
  uint32_t threshold_rejections = 0;  // candidates refused by the tolerance / theta_max
};

// One search's ray, relative to the cube centre: what its walk and its tests take.
struct SearchRay {
  glm::dvec3 w{0.0}, d{0.0};                               // origin and unit direction
  double l_max = std::numeric_limits<double>::infinity();  // end of the ray (shadow segments)
  double self = 0;               // self offset in world units (SELF-HITS, docs/design/search.md)
  double self_tolerance = 0;     // nearest tolerance candidate accepted, world units (SELF-HITS)
  bool restrict_object = false;  // refraction exit: only `object` and what may lie inside it
  uint32_t object = 0;
  bool side = true;  // SearchOptions::side_structure
};

// The rays the searches below walk: reflection_search's for (w, r), refraction_exit_search's
// for (w, t, object_id), shadow_search's for (p, light_position) (the segment; false, and no
// search, when p is the light).
SearchRay reflection_ray(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& r,
                         const SearchOptions& options = {});
SearchRay refraction_exit_ray(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& t, uint32_t object_id,
                              const SearchOptions& options = {});
bool shadow_ray(const SearchContext& ctx, const glm::dvec3& p, const glm::dvec3& light_position,
                const SearchOptions& options, SearchRay* out);

// CANDIDATES (docs/design/search.md): the fragments a search's walk hands to its crossing or
// thesis test, over the ray's whole walk (as if no answer ended it), in the order the walk
// meets them: those that pass the layer choice, the object restriction, the z-interval test
// (thesis 7.5) and the own-surface test. Each names the walk's texel (its place in the walk,
// CubeWalk's order) and the fragment (its index in the face's A-buffer), with the answer of
// MODE crossing's test for it, MESH REFINEMENT included where options.refine asks: where the
// ray meets a surface there (tested), at which l, how far from the triangle in texels
// (outside), on it to rounding (exact), accepted (valid), which triangle and facing, and the
// triangles the refinement tested. The BLOCK BOUNDS pass only texels none of whose fragments
// could pass, so they change none of it; the GPU's scan (host/gl/gl_cube_scan.hpp) is held
// to it.
struct ScanCandidate {
  uint32_t texel = 0;  // the walk's texel: 0 for the first it walks
  uint32_t face = 0;
  uint32_t fragment = 0;  // index into cube.faces[face].fragments
  int i = 0, j = 0;       // the texel on its face
  double l1 = 0;          // the end of the ray's interval in the texel
  double before_l1 = 0;   // the end of the texel walked before it (-inf for the first)
  bool tested = false, exact = false, valid = false, back_face = false;
  uint32_t triangle = 0;  // the surface found: the fragment's, or the one the refinement crossed
  double l = std::numeric_limits<double>::infinity();
  double outside = 0;
  uint32_t mesh_triangles = 0;
  // The same fragment of the same texel, with the same verdicts and triangle.
  bool same_place(const ScanCandidate& o) const {
    return texel == o.texel && face == o.face && fragment == o.fragment && i == o.i && j == o.j && tested == o.tested &&
           exact == o.exact && valid == o.valid && back_face == o.back_face && triangle == o.triangle &&
           mesh_triangles == o.mesh_triangles;
  }
};
struct CandidateScan {
  std::vector<ScanCandidate> candidates;
  uint32_t texels = 0;                                        // texels walked
  bool aborted = false;                                       // the walk's cap stopped it
  bool stopped = false;                                       // a STOP HINT (below) ended it
  double last_l1 = -std::numeric_limits<double>::infinity();  // when stopped: the end of its last texel
};
// STOP HINTS: where a scan may end before its walk does, from the crossings on their own
// triangle (crossing_candidate exact and valid with no MESH REFINEMENT: what a scan sees
// without refining). ScanStop::crossing ends it where MODE crossing's search would, were
// those its only crossings: CROSSING_WINDOW_TEXELS past the first texel holding one, at the
// first texel that ends beyond the nearest. ScanStop::shadow ends it after the texel where
// the segment crosses a triangle that lets no light through, before the light. A hint, not
// the choice: a crossing refined onto the mesh, a tie, or a blocker on a plane through its
// light can make the search read further, and search_from_candidates then says the scan is
// not complete.
enum class ScanStop : uint8_t { none, crossing, shadow };
CandidateScan scan_candidates(const SearchContext& ctx, const SearchRay& q, const SearchOptions& options = {},
                              ScanStop stop = ScanStop::none);

// The search of ray q (reflection_search's, or refraction_exit_search's for a restricted ray).
SearchResult search_along(const SearchContext& ctx, const SearchRay& q, const SearchOptions& options = {});

// The same search's answer from q's candidates (scan_candidates', or the GPU's): the crossing
// mode's choice among them and THE SIDE STRUCTURE, the code search_along runs on its own walk,
// so the answer is search_along's (same_answer) but for the walk's counts of texels, nodes
// and fragments read, which a list of candidates does not hold (left 0). The crossing mode over
// all layers only (InputError otherwise).
// `complete` (optional): false when the scan's walk was cut, by its cap (CandidateScan::aborted)
// or by a STOP HINT (stopped), before the choice stopped: the answer might then need the
// texels past the cut. True: the answer is the one the whole walk gives, whatever the cut.
SearchResult search_from_candidates(const SearchContext& ctx, const SearchRay& q, const SearchOptions& options,
                                    const CandidateScan& scan, bool* complete = nullptr);
// shadow_search's walk of segment q to the light at light_position (shadow_ray), without a
// known blocker.
ShadowResult shadow_along(const SearchContext& ctx, const SearchRay& q, const glm::dvec3& light_position,
                          const SearchOptions& options = {});
// shadow_search's answer (without a known blocker) from the candidates of its segment q to
// the light at light_position (shadow_ray), the same way.
ShadowResult shadow_from_candidates(const SearchContext& ctx, const SearchRay& q, const glm::dvec3& light_position,
                                    const SearchOptions& options, const CandidateScan& scan, bool* complete = nullptr);
// Whether an answer from candidates is the walked search's: same_answer but for the walk's
// counts of texels, nodes and fragments read.
bool same_found(const SearchResult& walked, const SearchResult& from_candidates);
bool same_found(const ShadowResult& walked, const ShadowResult& from_candidates);

// Reflection (or any secondary ray seen from outside): the first surface along the ray
// W + l R, l > 0 (W world space on the reflecting surface, R unit).
SearchResult reflection_search(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& r,
                               const SearchOptions& options = {});

// The next surface met by a ray inside object `object_id`: its first crossing, along W + l T (W
// world space, on the entry surface; T unit, refracted inwards), of that object's surface or of
// a surface of an object whose bounds meet its (REFRACTION, docs/design/search.md).
SearchResult refraction_exit_search(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& t,
                                    uint32_t object_id, const SearchOptions& options = {});

// The exact crossing of the ray W + l D (W world space, D unit) with the mesh around
// `triangle`: the edge-connected triangles within `radius` of the stretch
// [l_near - radius, l_near + radius] (MESH REFINEMENT). True with the triangle crossed and
// its l (the smallest); false when none is crossed or the flood gave up.
bool mesh_crossing(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& dir, uint32_t triangle,
                   double l_near, double radius, uint32_t* crossed, double* l);

// The surfaces crossed together with a search's answer (NESTED DIELECTRICS, media.hpp): every
// triangle other than `hit` that the ray W + l D (W world space, D unit) crosses exactly at
// an l within `tolerance` of `l_hit`. Asked of the map: the fragments, in the 3 x 3 texels
// around the point, whose depth range reaches it, each with the mesh around its triangle
// (MESH REFINEMENT), and the side structure. visit(triangle, l) once per triangle.
void coincident_crossings(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& d, uint32_t hit,
                          double l_hit, double tolerance, const std::function<void(uint32_t, double)>& visit);

// Visibility of point light `light_position` from surface point p (world space).
//
// KNOWN BLOCKER. `known_blocker` (or NO_TRIANGLE) names a triangle expected to block the
// segment: the opaque one that stopped a nearby point's segment to the same light
// (ShadowResult::opaque_blocker). Before the walk it is tested exactly, by THE SIDE
// STRUCTURE's rules: the watertight test (reference/triangle_test.hpp) between p and the
// light, beyond the self offset, not p's own surface, its plane not through the light. When
// it passes, the segment is blocked (transmittance 0) and the map is not walked: an opaque
// triangle the segment crosses blocks it whatever else lies on it, so that answer is the
// exact one, and the walk's differs from it only where the walk would have missed that
// triangle. Crossing mode over all layers, with THE SIDE STRUCTURE, only
// (SearchOptions::known_blockers): the thesis mode and the Z-buffer keep the answers of the
// methods they reproduce, and a search of the map alone (--map-only) sees only the map.
ShadowResult shadow_search(const SearchContext& ctx, const glm::dvec3& p, const glm::dvec3& light_position,
                           const SearchOptions& options = {}, uint32_t known_blocker = NO_TRIANGLE);
// shadow_search's KNOWN BLOCKER alone: true, with its answer in *out, when the options take a
// known blocker and `known_blocker` stops segment q (shadow_ray) to the light; false when the
// segment must be walked.
bool known_blocker_answer(const SearchContext& ctx, const SearchRay& q, const glm::dvec3& light_position,
                          const SearchOptions& options, uint32_t known_blocker, ShadowResult* out);

// Whether two searches gave the same answer bit for bit: every field but the walk's counts
// of texels and nodes (HIERARCHICAL SKIP: on and off must agree).
bool same_answer(const SearchResult& a, const SearchResult& b);
bool same_answer(const ShadowResult& a, const ShadowResult& b);

// Counters of one kind of search.
struct SearchKindStats {
  uint64_t rays = 0;
  uint64_t texels = 0, max_texels = 0;  // texels visited: sum and max per ray
  uint64_t nodes = 0;                   // pyramid nodes stepped over (HIERARCHICAL SKIP)
  uint64_t fragments = 0;               // z-interval tests
  uint64_t candidates = 0;              // fragments refined
  uint64_t mesh_triangles = 0;          // triangles MESH REFINEMENT tested for a crossing
  uint64_t hits = 0;                    // shadows: rays with a blocker
  uint64_t misses = 0;                  // every miss, whatever the reason; shadows: unblocked
  uint64_t threshold_rejections = 0;    // misses whose best candidate failed the threshold
  uint64_t zero_area = 0;               // misses on a surface through the centre (map only)
  uint64_t side_hits = 0;               // answered by THE SIDE STRUCTURE; shadows: rays with a side blocker
  uint64_t known_blockers = 0;          // shadows: answered by their KNOWN BLOCKER, the map not walked
  uint64_t aborted = 0;                 // walks stopped by the cap
  double mean_texels() const { return rays ? static_cast<double>(texels) / static_cast<double>(rays) : 0.0; }
  double mean_nodes() const { return rays ? static_cast<double>(nodes) / static_cast<double>(rays) : 0.0; }
  void add(const SearchResult& r);
  void add(const ShadowResult& r);
  void merge(const SearchKindStats& o);
};

struct SearchStats {
  SearchKindStats reflection, refraction_exit, shadow;
  void merge(const SearchStats& o);
};

}  // namespace abcube
