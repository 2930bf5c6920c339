// GPU against CPU, texel by texel and pixel by pixel (`abcube crosscheck`):
// the GL distance prepass against the CPU A-buffer's nearest layer, the GPU's cube A-buffer
// (gl_abuffer.hpp) against the CPU's list by list, and the GL Z-buffer camera image against
// the CPU A-buffer's resolved image away from silhouettes.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "raster/abuffer.hpp"
#include "raster/abuffer_compare.hpp"
#include "gl/gl_cube_scan.hpp"
#include "gl/gl_cube_walks.hpp"
#include "gl/gl_passes.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

// The documented tolerances; `abcube crosscheck` exits 1 beyond any of them. Each lies with
// a margin above what the repository scenes reach at N = 96..512, on EGL and OSMesa alike,
// and below what a real disagreement gives (docs/performance.md has the figures). The
// largest distance error is always a handful of silhouette texels, where the GPU's
// texel-centre sample and the CPU's four centre samples see different surfaces: that is
// why the tolerances are on the median and p99. Interior pixels are shaded at one point of
// one triangle on both sides (crosscheck.cpp interior_pixel): what remains is float against
// double and the fragment's 32-bit normal. On a large bench mesh at coarse N, merged
// fragments span many triangles and the p99 may exceed its tolerance below N = 512.
struct CrosscheckTolerances {
  double distance_median_rel = 1e-6;  // |gpu - cpu| / cpu over texels covered on both
  double distance_p99_rel = 1e-4;
  double same_object_min = 0.995;       // share of those texels with the same object id
  double coverage_mismatch_max = 0.01;  // share of texels covered on one path only
  // Camera view, displayed values, interior pixels (one triangle over the whole pixel and
  // its centre: both sides shade the same point, so only float rounding remains).
  double interior_rmse = 1e-4;
  double interior_max_abs = 1.0 / 255.0;
  double sample_agreement_min = 0.9999;  // camera samples where GPU and CPU see the same object (or none)
  // Shadows sample by sample, away from shadow edges: the GPU's shadow volumes against the
  // exact tracer.
  double volumes_agreement_min = 0.999;
};

// The shadow comparison's camera: the scene's, at most this many pixels wide (aspect kept).
constexpr int SHADOW_CHECK_MAX_WIDTH = 160;

// One shadow technique against the exact tracer, over (sample, light) pairs where both the
// GPU and the tracer see the same object and it faces the light (N.L above 1e-3: below it
// the light adds less than a thousandth of its diffuse term, and whether a grazing segment
// is blocked is decided by rounding: a light lying on a floor): agreement over all of
// them, and over those away from shadow edges (the tracer's verdict and the object the
// same at the 8 neighbouring samples of the 4x8 grid).
struct ShadowAgreement {
  size_t pairs = 0, agree = 0, interior = 0, interior_agree = 0;
  size_t false_shadow = 0, false_light = 0;  // shadowed where the tracer lights, and the reverse
  double share() const { return pairs ? double(agree) / double(pairs) : 1.0; }
  double interior_share() const { return interior ? double(interior_agree) / double(interior) : 1.0; }
};

struct CrosscheckResult {
  // Cube map: GL prepass vs CPU A-buffer nearest layer (NearestLayer in abuffer.hpp).
  size_t texels = 0, both_covered = 0, gpu_only = 0, cpu_only = 0;
  double distance_median_rel = 0, distance_p99_rel = 0, distance_max_rel = 0;
  double same_object = 0;  // over every texel covered on both, exact ties included
  // Texels where the two differ (in object, or covered on one side only) and whose centre
  // lies within EDGE_TIE_EPS texels of a triangle's edge (edge_ties.hpp): GL's snapped
  // vertices may put the centre on either side. Counted apart, in none of the figures here.
  size_t texels_edge_ties = 0;
  // Exact ties (tie_rule.hpp): texels covered on both where the CPU's nearest layer had
  // two objects over one centre sample at the same distance, and of those the ones where
  // the GPU's object is the one the rule picked (the later object). Reported apart: they
  // test the GL's depth scaling of THE TIE RULE, not the two rasterisers.
  size_t tied = 0, tied_agree = 0;
  // Camera view: interior pixels (one opaque full-coverage front fragment, nothing
  // intersecting it) of the CPU A-buffer image against the GL Z-buffer image.
  size_t pixels = 0, interior_pixels = 0;
  double interior_rmse = 0, interior_max_abs = 0;
  // Camera visibility sample by sample: at each of the 4x8 samples of every pixel, the
  // object the GPU's Z-buffer sees against the one the CPU A-buffer's masks and exact
  // priority masks say is nearest (resolve.hpp visible_triangles).
  size_t samples = 0, samples_same = 0, samples_gpu_only = 0, samples_cpu_only = 0, samples_other_object = 0;
  size_t samples_edge_ties = 0;  // differing, within EDGE_TIE_EPS of an edge: not in sample_agreement
  double sample_agreement = 0;
  // Per pixel, how many of its 32 samples disagree (an image for `crosscheck --samples-image`).
  Image sample_disagreement;
  Image cpu_image;  // the CPU A-buffer's camera image with local Phong (what interior pixels compare)
  // Shadows: the GPU's shadow volumes and cube shadow maps, and the CPU's shadow search
  // in the cube A-buffer, each against the exact tracer, sample by sample, on the first
  // 16 shadow-casting lights; `shadow_disagreement`: per pixel, the share of its (sample,
  // light) pairs where the volumes and the tracer differ.
  int shadow_width = 0, shadow_height = 0, shadow_lights = 0;
  ShadowAgreement volumes, maps, search;
  Image shadow_disagreement;
  // The GPU's cube A-buffer against the CPU's, fragment by fragment (compare_lists): it
  // fails beyond LIST_DEPTH_REL and LIST_NORMAL_STEPS, or on any other difference.
  ListComparison lists;
  double gpu_abuffer_ms = 0;
  ListComparison camera_lists;  // the same for the camera's A-buffer
  double gpu_camera_abuffer_ms = 0;
  // THE RESOLVE PLAN made on the GPU (gl_resolve_plan.hpp) and run by the CPU against
  // cpu_image's resolve: the pixels whose colours are the same bits, of those planned.
  struct ResolvePlanCheck {
    size_t pixels = 0, planned = 0, identical = 0;
    uint64_t steps = 0;
    std::string example;  // the first pixel not identical
    std::string skipped;  // why the plan was not compared (a GL or budget refusal)
    std::string probe;    // THE PROBE's verdict (gl_resolve_plan.hpp): empty, it agrees
    double ms = 0;
  } resolve_plan;
  // The cube walks of the searches' rays (shadow segments to the lights and reflection rays
  // from points on the triangles) on the GPU against CubeWalk's, texel for texel
  // (gl_cube_walks.hpp compare_walks): it fails on any walk differing beyond rounding. Not
  // compared where N is above what a GPU walk takes (gpu_walks_at).
  WalkComparison walks;
  double gpu_walks_ms = 0;
  std::string walks_skipped;  // why the walks were not compared ("" when they were)
  // The searches' candidates (reflection rays, shadow segments, refraction exits) found on
  // the GPU in the CPU's cube A-buffer against the CPU's (gl_cube_scan.hpp
  // compare_candidate_scans): it fails on any ray differing, unless some walk differed within
  // rounding (a GL whose doubles do not round as IEEE 754 says). Not compared where the walks
  // are not, or where the scene's lists are beyond what the GPU's scan takes.
  CandidateComparison candidates;
  double gpu_candidates_ms = 0;
  std::string candidates_skipped;  // why not ("" when they were compared, or the walks say)
  // The searches' answers from the GPU's candidates (search_from_candidates for reflections
  // and refraction exits, shadow_from_candidates for shadow segments) against the CPU's
  // searches (same_found): it fails on any answer not the same, as the candidates.
  struct Answers {
    size_t rays = 0, same = 0, found = 0;  // found: a hit, or a shadow segment blocked
    std::string example;                   // the first ray not the same, in words
  } answers;
  // One small camera image (64 pixels wide at most) rendered by the map method twice, its
  // searches walked on the CPU, then answered from GPU candidates in deferred passes: the
  // count of pixels apart by more than 1/255 (sRGB, any channel), the worst gap, and byte
  // equality. Fails when over 0.1% of pixels are apart. Only where candidates are compared.
  struct SearchImages {
    int width = 0, height = 0;
    uint64_t passes = 0;
    bool same_bytes = false;
    size_t differing = 0;
    double max_diff = 0, ms = 0;
  } search_images;
  double gpu_ms = 0, cpu_ms = 0;  // prepass vs cube A-buffer build
  uint64_t fragments = 0;
  bool pass = false;
  std::string failures;  // which tolerances failed, "" when pass
};

// The triangles whose searches' rays (scene_walk_rays, scene_search_rays) the crosscheck
// walks and scans both ways.
constexpr size_t CROSSCHECK_WALK_TRIANGLES = 1024;

// The searches' part of a crosscheck over the CPU's cube A-buffer `cube` of `scene`: the
// GPU's candidates, the answers made from them, and the image shaded with them (candidates,
// answers, search_images in r; a GL context must be current).
void compare_searches(const SceneData& scene, const CubeABuffer& cube, int threads, CrosscheckResult* r);
// That part of the crosscheck's stats ("search_candidates").
nlohmann::json search_candidates_json(const CrosscheckResult& r);

// Runs both paths on `scene` (a GL context must be current) with n x n faces.
CrosscheckResult crosscheck(const SceneData& scene, int n, int threads, const CrosscheckTolerances& tol = {});

// A one-channel share in [0, 1] a pixel (sample_disagreement, shadow_disagreement) drawn
// so that a person sees where: `base` (same size, or empty for a dark grey) in grey at half
// brightness, and every pixel whose share is above 0 in red, to yellow at a share of 1.
Image disagreement_overlay(const Image& share, const Image& base);

nlohmann::json crosscheck_json(const CrosscheckResult& r, const CrosscheckTolerances& tol);

}  // namespace abcube
