// Shading with the cube map: the `abuffer`, `zbuffer` and `envmap` methods (thesis 7, 8.3,
// 9). The SAME rules as the exact tracer (raytrace.hpp "THE RULES"), with every ray query
// but the camera's answered from the one cube map centred on the camera: abuffer searches
// all layers (multi-bounce), zbuffer the nearest layer only (Patow 1995), envmap looks the
// map's colour up in one direction (Blinn & Newell 1976; no bounce) and casts the same
// shadows as abuffer, so that comparing the methods isolates the lookups. Nested dielectrics
// are decided as the tracer decides them (media.hpp). docs/design/map-shading.md has the
// whole argument.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "raster/abuffer.hpp"
#include "io/image.hpp"
#include "search/lens.hpp"
#include "shading/resolve.hpp"
#include "io/metrics.hpp"
#include "scene/scene_data.hpp"
#include "reference/raytrace.hpp"
#include "search/deferred_searches.hpp"
#include "search/search.hpp"
#include "material/shading.hpp"
#include "shading/shading_plan.hpp"

namespace abcube {

class RayTracer;
class SceneCache;

enum class EnvmapLookup { reflected, bisector, position };  // R, [[R + [[W]]]], [[W]]
const char* envmap_lookup_name(EnvmapLookup l);
bool parse_envmap_lookup(const std::string& s, EnvmapLookup* out);  // "R" | "bisector" | "position"

// What a map search returns (thesis 7.2, 7.3, 5.6): the abuffer method's searches through
// every layer of the lists, the zbuffer method's through the nearest layer only, or the
// envmap method's lookups in the map's colours with no search.
enum class MapVariant { abuffer, zbuffer, envmap };

struct MapShadingOptions {
  MapVariant variant = MapVariant::abuffer;
  SearchOptions search;  // layers are set from the variant
  RefractionMode refraction = RefractionMode::search;
  EnvmapLookup lookup = EnvmapLookup::reflected;
  int threads = 0;
  // --plan everything: also walk the shadows of lights that cast none (result unused), to
  // measure what the plan's skip saves. The image does not change.
  bool walk_all_shadows = false;
  // The resolve of intersecting fragments (resolve.hpp): exact priority masks, or the
  // thesis' Vis_front estimate (--resolve thesis).
  bool exact_priority = true;
  // Shading points per camera fragment, and the edges refined at the samples
  // (shading_plan.hpp; SPARSE, SHADOW EDGES and SECONDARY EDGES below). One point, at the
  // centroid of its covered samples, takes about half the shading of a covered pixel; an
  // edge of a shadow or a reflection inside the pixel is then all or nothing. A textured
  // fragment's base colour is averaged over the covered samples each shading point stands
  // for (render_with_map), or looked up at the point.
  ShadingPlan plan;
};

// Ray-level error against the exact tracer (thesis ch. 9), for the reflection rays of
// primary surfaces: Error_CP of the lookup direction and Error_Parallax of the found point.
struct RayErrors {
  ErrorStats error_cp, error_parallax;
  uint64_t false_hits = 0;  // the method found a point, the exact ray meets nothing
  uint64_t wrong_object = 0;
  void merge(const RayErrors& o);
};

struct MapShadingStats {
  SearchStats searches;
  uint64_t lens_transfers = 0, lens_fallbacks = 0;  // fallbacks: transfer refused, searched
  uint64_t envmap_lookups = 0;
  // Camera fragments shaded at more than one point; those refined at a shadow edge (SHADOW
  // EDGES), the sample shadow searches they made, and the pixels shaded a second time for
  // an edge beside them.
  uint64_t multi_point_fragments = 0, shadow_edge_fragments = 0, shadow_edge_samples = 0, shadow_edge_pixels = 0;
  // Camera fragments with a secondary term shaded at each covered sample (SECONDARY EDGES),
  // the samples shaded, and the pixels shaded a second time for an edge beside them.
  uint64_t secondary_edge_fragments = 0, secondary_edge_samples = 0, secondary_edge_pixels = 0;
  // --shading-points sparse: the pixels shaded again at their quarters (SPARSE).
  uint64_t sparse_pixels = 0;
  RayErrors errors;  // filled only when a reference tracer is given
  void merge(const MapShadingStats& o);
};

// Where a camera fragment is shaded (render_with_map): at up to four points of its
// triangle's plane, the centroids of its covered samples in each 4x2 quarter of the 4x8
// mask, weighted by their sample counts. One shading point per fragment would make an edge
// through the pixel of anything its shading depends on (a hard shadow, a silhouette seen in
// a mirror or through glass) all or nothing, where the tracer averages its 32 samples.
// ADAPTIVE: the first and last covered quarters (the diagonal when all four are) are
// shaded; only where their colours differ by more than QUARTER_SPLIT_SRGB (sRGB-encoded, any
// channel) are the others shaded too, else they take the mean of the two.
// docs/design/map-shading.md says where this matters.
constexpr double QUARTER_SPLIT_SRGB = 1.0 / 255.0;
//
// SPARSE (--shading-points sparse). Each fragment shaded at one point first; then the pixels
// whose colour differs from a 4-neighbour's by more than SPARSE_SPLIT_SRGB (sRGB-encoded, any
// channel: an edge of a shadow, of a silhouette, of what a mirror or glass shows) are shaded
// again, their fragments at the adaptive quarters. Elsewhere the pixel is smooth, and one
// point stands for it as well as the quarters would (docs/performance.md measures how
// close). There is no SHADOW EDGES or SECONDARY EDGES pass; inside the pixels shaded again,
// SECONDARY EDGES refine mirror and glass fragments as with the quarters (shading_plan.hpp).
constexpr double SPARSE_SPLIT_SRGB = 16.0 / 255.0;
//
// SHADOW EDGES (shadow_edges.hpp). A shadow's edge through a fragment would still be
// decided at those points: a step a pixel where the tracer's 32 samples make a ramp. The
// colour of a primary point is linear in each light's visibility S_l (shading.hpp: the
// local term is sum_l S_l * phong_light_l), so where the shaded points' S_l differ for some
// light, that light's shadow is searched again from every covered sample (its point of the
// triangle's plane, moved onto the mesh as the shading points are), and each quarter's
// colour takes the mean S_l of its samples in place of its point's:
// c_q += phong_light_l(q) * (mean - S_l(q)). Every quarter is then shaded, so that each has
// its own phong_light_l.
// An edge can also pass between the points, meeting none of them: then the pixel's points
// all see one answer and a neighbour's points the other. And a shadow thinner than the
// points' spacing (a spider's leg) is met by a point here and there along its length, and
// runs on into the next pixels between their points. A second pass shades again the pixels
// whose points saw a light (of the first 64) only lit where a 4-neighbour's saw it only
// shadowed, or the reverse; and those whose points saw it only lit next to a neighbour whose
// points disagreed and whose samples found a shadowed one on the side the two pixels share
// (PixelShadows::sides), or the reverse. Those lights are refined in all their fragments.
// Where all agree nothing changes and nothing more is searched: the cost falls where edges
// are (the stats' "shadow_edges"). A shadow thinner than the points' spacing, met by no
// point of a pixel or its neighbours, is not seen.
//
// SECONDARY EDGES. A mirror's or glass's fragment shows what its reflected and refracted
// rays find, and an edge of that (a silhouette, a model's thin leg seen in the chrome or
// through the glass) would be decided at the points too. So every covered quarter of such a
// fragment (a material with kr or kt, bounces left) is shaded; where their secondary rays
// found different surfaces (PrimaryLights::trail) and their colours differ by more than
// QUARTER_SPLIT_SRGB, each quarter's kr and kt terms become the mean of its covered
// samples', each searched from the sample's own point, as the tracer's 32 rays see the pixel
// (--secondary-edges samples; the stats' "secondary_edges"). The quarter keeps its own
// light, its shadows refined as SHADOW EDGES says: the colour is the light plus those terms,
// and only the terms change across an edge of what the mirror shows. Quarters that see one
// surface keep their points' colours, however that surface's shading varies: the cost falls
// on the fragments a silhouette of the secondary image crosses.

// The direct light one primary point received, light by light (scene.lights' order):
// `lit` the unshadowed term (phong_light; 0 where the light is behind the surface), `shadow`
// the visibility its shadow search gave (1 for a light that casts no shadow).
struct PrimaryLights {
  std::vector<glm::dvec3> lit, shadow;
  // The objects the point's secondary rays found (reflected, transmitted, through coverage
  // transparency, at every depth; 0 for a miss), hashed in the order they were found: two
  // points whose trails differ see different surfaces in a mirror or through glass.
  uint64_t trail = 0;
  // The point's kr and kt terms: its colour less its own light (SECONDARY EDGES).
  glm::dvec3 secondary{0.0};
};

// KNOWN BLOCKERS (search.hpp shadow_search): per light, the opaque triangle that stopped the
// last shadow segment one worker searched to it (NO_TRIANGLE when none), tried first by its
// next search to that light: neighbouring points' segments to one light are mostly stopped by
// the same triangle (docs/design/map-shading.md, "Known blockers"). A render
// keeps one per worker and clears it when the worker starts a row, so that a pixel's shadows
// depend only on the pixels before it in its row, whatever the threads.
struct KnownBlockers {
  std::vector<uint32_t> triangle;  // by light index; empty: none known
  uint32_t of(size_t light) const { return light < triangle.size() ? triangle[light] : NO_TRIANGLE; }
  void note(size_t light, uint32_t blocker) {
    if (triangle.size() <= light) triangle.resize(light + 1, NO_TRIANGLE);
    triangle[light] = blocker;
  }
  void clear() { triangle.clear(); }
};

// A point on a triangle: what the rules need to shade it.
struct SurfacePoint {
  glm::dvec3 point{0.0};
  glm::dvec3 geometric_normal{0.0};  // unit, cross(b-a, c-a)
  glm::dvec3 shading_normal{0.0};    // unit, interpolated vertex normals
  uint32_t triangle = 0, object = 0, material = 0;
  // Od given by the caller (render_with_map: a textured camera fragment's base colour
  // averaged over the samples its shading point stands for), else looked up at `point`.
  bool diffuse_given = false;
  glm::dvec3 diffuse{0.0};
};
SurfacePoint surface_point(const SceneData& scene, uint32_t triangle, const glm::dvec3& point);

class MapShader {
 public:
  // `cube` is the map around scene.camera.position. `reference` (optional) is the exact
  // tracer the ray errors are measured against. All must outlive the shader.
  // `cache` (optional) holds the per-scene data (mesh neighbours, lens fits) built once
  // for every render of the scene; without it they are built here.
  MapShader(const SceneData& scene, const CubeABuffer& cube, const MapShadingOptions& options,
            const RayTracer* reference = nullptr, const SceneCache* cache = nullptr);
  // A shader with other options over `base`'s map, sharing its search structures (its
  // SearchContext, built once per map) and copying its lens fits: another shading plan on
  // the same map. The options' method and refraction must be base's.
  MapShader(const MapShader& base, const MapShadingOptions& options, const RayTracer* reference = nullptr);
  ~MapShader();

  // The colour of surface point `sp` seen along unit `dir` at bounce `depth`. `primary`
  // marks a camera fragment: its coverage transparency is the resolve's business, and
  // its reflection rays are the ones measured against the reference.
  // `direct` (optional) receives what the point's own lights gave it (depth 0 only).
  // `known` (optional): the caller's KNOWN BLOCKERS, used and updated by every shadow search.
  glm::dvec3 shade(const SurfacePoint& sp, const glm::dvec3& dir, int depth, bool primary, MapShadingStats* stats,
                   PrimaryLights* direct = nullptr, KnownBlockers* known = nullptr) const;
  // A camera fragment's point's kr and kt terms alone (what `shade` adds to its own light),
  // `trail` (optional) receiving PrimaryLights::trail.
  glm::dvec3 secondary(const SurfacePoint& sp, const glm::dvec3& dir, MapShadingStats* stats, uint64_t* trail,
                       KnownBlockers* known = nullptr) const;
  // S_l of light number `light` at `p`: the shadow search's transmittance (thesis 8.3).
  glm::dvec3 visibility(const glm::dvec3& p, size_t light, MapShadingStats* stats,
                        KnownBlockers* known = nullptr) const;

  // The path of the transmitted weight alone from `origin` (in air, not a surface) along
  // `dir`, answered by the searches: the ray after each interface, as
  // RayTracer::transmitted_path (the same rules), at most `max_rays`.
  std::vector<Ray> transmitted_path(const glm::dvec3& origin, const glm::dvec3& dir, int max_rays) const;

  const std::vector<LensFit>& lenses() const { return lenses_; }
  const SearchContext& context() const { return *ctx_; }
  // DEFERRED SEARCHES (search/deferred_searches.hpp): `d` (null: none) answers every search
  // and shadow walk of the renders that follow, and render_with_map runs its passes until
  // none is left unanswered. It must outlive its use; its options must be this shader's.
  void defer_searches(DeferredSearches* d) { deferred_ = d; }
  DeferredSearches* deferred() const { return deferred_; }
  // THE RESOLVE PLAN (resolve.hpp) of the camera A-buffer the renders that follow resolve
  // (null: none, pack_under_mask alone): every resolve of render_with_map runs its steps.
  void plan_resolve(const ResolvePlan* plan) { resolve_plan_ = plan; }
  const ResolvePlan* resolve_plan() const { return resolve_plan_; }
  // SearchRefine::mesh (docs/design/search.md, MESH REFINEMENT): besides the crossing searches'
  // candidates, camera fragments' shading points are moved onto the surface the same way (any
  // mode).
  bool refines_on_mesh() const { return options_.search.refine == SearchRefine::mesh; }
  bool exact_priority() const { return options_.exact_priority; }
  const MapShadingOptions& options() const { return options_; }
  bool one_point() const { return options_.plan.one_point(); }
  bool quarters_at_edges() const { return options_.plan.sparse(); }
  bool shadow_edges() const { return options_.plan.shadow_edges(); }
  bool texture_samples() const { return options_.plan.texture_samples(); }
  bool secondary_edges() const { return options_.plan.secondary_edges(); }

 private:
  // A crossing set (media.hpp): the surface point shaded, the furthest crossing, the interface.
  struct Crossed {
    SurfacePoint sp;
    glm::dvec3 far{0.0};
    Interface itf;
  };
  // `defer`: the deferred searches answer it, when there are.
  SearchResult search(const glm::dvec3& w, const glm::dvec3& dir, const MediumStack& stack, MapShadingStats* stats,
                      bool defer = true) const;
  // shadow_search of p to the light at light_position, or its deferred answer.
  ShadowResult shadow(const glm::dvec3& p, const glm::dvec3& light_position, uint32_t known_blocker) const;
  Crossed crossing_set(const glm::dvec3& w, const glm::dvec3& dir, const SearchResult& r,
                       const MediumStack& stack) const;
  // `trail` (optional): the surfaces every search below this one found, hashed in order
  // (PrimaryLights::trail).
  glm::dvec3 shade(const Crossed& c, const glm::dvec3& dir, int depth, bool primary, MapShadingStats* stats,
                   KnownBlockers* known, PrimaryLights* direct, uint64_t* trail) const;
  struct Terms {
    glm::dvec3 reflected{0.0}, transmitted{0.0};
  };
  Terms secondary_terms(const Crossed& c, const glm::dvec3& dir, int depth, bool primary, MapShadingStats* stats,
                        KnownBlockers* known, uint64_t* trail) const;
  Ray transmitted_ray(const Crossed& c, const Transmission& tr, MediumStack* stack) const;
  glm::dvec3 trace(const glm::dvec3& w, const glm::dvec3& dir, int depth, const MediumStack& stack,
                   MapShadingStats* stats, KnownBlockers* known, SearchResult* found, uint64_t* trail) const;
  glm::dvec3 lights(const SurfacePoint& sp, const glm::dvec3& v, const glm::dvec3& n, const glm::dvec3& od,
                    MapShadingStats* stats, KnownBlockers* known, PrimaryLights* direct) const;
  glm::dvec3 reflected(const SurfacePoint& sp, const glm::dvec3& dir, int depth, bool primary, const MediumStack& stack,
                       MapShadingStats* stats, KnownBlockers* known, uint64_t* trail) const;
  glm::dvec3 transmitted(const Crossed& c, const glm::dvec3& dir, int depth, MapShadingStats* stats,
                         KnownBlockers* known, uint64_t* trail) const;
  glm::dvec3 envmap_direction(const glm::dvec3& w, const glm::dvec3& r) const;
  glm::dvec3 envmap_at(const glm::dvec3& direction) const;
  void measure(const SurfacePoint& sp, const glm::dvec3& r, const SearchResult* found, const glm::dvec3* lookup,
               MapShadingStats* stats) const;
  glm::dvec3 envmap_texel(int face, int i, int j) const;

  const SceneData& scene_;
  const CubeABuffer& cube_;
  MapShadingOptions options_;
  const RayTracer* reference_;
  void set_method_state();  // the search layers and envmap's texel cache, from options_.method

  std::shared_ptr<SearchContext> ctx_;
  DeferredSearches* deferred_ = nullptr;
  const ResolvePlan* resolve_plan_ = nullptr;
  std::vector<LensFit> lenses_;
  std::vector<int> lens_of_object_;  // index into lenses_, -1 if none
  // envmap: the resolved colour of each texel looked up so far (envmap_at).
  mutable CubeImage env_colour_;
  std::unique_ptr<std::atomic<uint8_t>[]> texel_state_;
};

// The camera view through the camera A-buffer, every fragment shaded by `shader`, resolved
// by Pack_Under_Mask (resolve.hpp). Stats merged over threads. `fallback` (optional, 1
// channel): per pixel, the share of its fragments' secondary searches that found nothing
// (a reflection or refraction-exit miss, a shadow walk on a zero-area surface or
// aborted, a lens transfer refused), 0 where none was made.
// `only` (optional): the pixels to render (ResolveOptions::only); the others stay black.
// With `only`, SHADOW EDGES between pixels need the neighbours' points too: `neighbours`
// shades the 4-neighbours of `only`'s pixels as well (their colours are dropped); without
// it an edge between an `only` pixel and one outside is left to the points (the pilots of
// --target-db, single pixels apart, would pay five pixels for one). `progress` (optional):
// called on the calling thread with the share of the shading done.
Image render_with_map(const SceneData& scene, const ABuffer& camera, const MapShader& shader, int threads,
                      MapShadingStats* stats, Image* fallback = nullptr, const std::vector<uint8_t>* only = nullptr,
                      bool neighbours = true, const std::function<void(double)>* progress = nullptr);

}  // namespace abcube
