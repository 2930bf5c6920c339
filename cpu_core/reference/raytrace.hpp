// The exact reference: a Whitted ray tracer (Whitted 1980) over the scene's triangles, in
// double precision, against which every other method's images and searches are measured
// (metrics.hpp; thesis ch. 9). THE RULES, shared by every method (their functions live in
// shading.hpp): 4x8 camera samples a pixel, box-filtered; the nearest hit, ties by THE TIE
// RULE; Phong plus kr, kt terms to max_depth; nested dielectrics (media.hpp); shadows as the
// product of blocker transmittances; secondary rays offset off the surface. Hits are the
// watertight double test through Embree's BVH (bvh.hpp), and the image is bit-identical for
// any number of threads. docs/design/raytrace.md has the rules in full.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "reference/bvh.hpp"
#include "io/image.hpp"
#include "scene/scene_data.hpp"
#include "material/media.hpp"

namespace abcube {

// The ladder's rungs below 32 samples (samples.hpp THE SAMPLE LADDER): 1, 2, 4, 8, 16.
constexpr int LOWER_RUNGS = 5;

struct RaytraceOptions {
  int threads = 0;  // 0 = std::thread::hardware_concurrency()
  // A rung of THE SAMPLE LADDER (samples.hpp): 32 (the 4x8 A-buffer samples, the reference),
  // 16, 8, 4, 2 (the ladder's first samples) or 1 (the pixel's centre).
  int samples_per_pixel = 32;
  // For pilots: with 32 samples a pixel, each traced pixel also gets, in (*rungs)[i], the value
  // it has at 2^i samples a pixel (the same bits a render at that rung gives it).
  std::array<Image, LOWER_RUNGS>* rungs = nullptr;
  // Called now and then on the calling thread with the share of rows done, in [0, 1].
  std::function<void(double)> progress;
  // The scene's BVH when already built (SceneCache); null: built for this render.
  std::shared_ptr<const Bvh> bvh;
  // Width x height, row-major: only the pixels marked non-zero are traced, the others
  // left black (the hybrid method's pixels of edge_ties.hpp); null: every pixel.
  const std::vector<uint8_t>* only = nullptr;
};

struct RaytraceStats {
  uint64_t primary_rays = 0;
  uint64_t secondary_rays = 0;  // reflected, transmitted and opacity-continued rays
  uint64_t shadow_rays = 0;
  double build_ms = 0;  // BVH construction (Embree's, bvh.hpp)
  double trace_ms = 0;  // all rays of the image
  uint64_t triangles = 0;
  int threads = 0;  // threads actually used
};

// Per-thread ray counters (RaytraceStats sums them).
struct RayCounts {
  uint64_t primary = 0, secondary = 0, shadow = 0;
};

// Everything about the first surface a ray meets.
struct Hit {
  double t = 0;                      // origin + t * dir (t in units of |dir|)
  glm::dvec3 point{0.0};             // on the triangle: barycentric combination of its vertices
  uint32_t triangle = 0;             // index into SceneData::triangles
  glm::dvec3 barycentric{0.0};       // weights of the triangle's vertices 0, 1, 2
  glm::dvec3 geometric_normal{0.0};  // unit, cross(b-a, c-a) direction
  glm::dvec3 shading_normal{0.0};    // unit, interpolated vertex normal (not face-forwarded)
  uint32_t object_id = 0;            // index into SceneData::objects
  uint32_t material_id = 0;          // index into SceneData::materials
  bool front_face = true;            // dot(geometric_normal, dir) < 0
};

// A secondary ray: origin already offset off the surface, unit direction.
struct Ray {
  glm::dvec3 origin{0.0}, dir{0.0};
};

class RayTracer {
 public:
  // Builds the BVH, or uses `bvh` (built on the same triangles, shared by every render of
  // a scene: SceneCache). The scene must outlive the tracer (referenced, not copied).
  explicit RayTracer(const SceneData& scene, std::shared_ptr<const Bvh> bvh = nullptr);
  explicit RayTracer(SceneData&&) = delete;

  // The first hit with 0 < t < tmax along origin + t*dir (dir non-zero, need not be unit).
  bool intersect(const glm::dvec3& origin, const glm::dvec3& dir, double tmax, Hit* hit) const;
  bool intersect(const glm::dvec3& origin, const glm::dvec3& dir, Hit* hit) const;

  // The colour seen along a ray of depth `depth` (dir need not be unit). Counts rays into
  // `counts` when given (the ray itself is counted by the caller: see render_raytrace).
  glm::dvec3 trace(const glm::dvec3& origin, const glm::dvec3& dir, int depth, RayCounts* counts = nullptr) const;
  // The same for a ray inside the media of `stack` (media.hpp, NESTED DIELECTRICS).
  glm::dvec3 trace(const glm::dvec3& origin, const glm::dvec3& dir, int depth, const MediumStack& stack,
                   RayCounts* counts) const;

  // The colour of a hit seen along unit dir, at depth `depth`, by a ray in air (THE RULES).
  glm::dvec3 shade(const Hit& hit, const glm::dvec3& dir, int depth, RayCounts* counts) const;

  // The path of the transmitted weight alone from origin along dir (camera in air): the ray
  // after each interface it crosses (NESTED DIELECTRICS; total internal reflection gives the
  // mirror ray), at most `max_rays` of them, until a ray meets nothing or a surface with
  // kt = 0. What trace() follows for the kt terms: tests check it against Snell's law.
  std::vector<Ray> transmitted_path(const glm::dvec3& origin, const glm::dvec3& dir, int max_rays) const;

  // S_l: the light's visibility from surface point `hit` (1 when it casts no shadows).
  glm::dvec3 light_visibility(const Hit& hit, const PointLight& light, RayCounts* counts) const;

  // The secondary rays of a hit seen along unit dir (THE RULES; transmitted_ray: the
  // hit's object in air).
  Ray reflected_ray(const Hit& hit, const glm::dvec3& dir) const;
  Ray transmitted_ray(const Hit& hit, const glm::dvec3& dir, bool* total_internal_reflection) const;
  Ray continued_ray(const Hit& hit, const glm::dvec3& dir) const;

  // The hit point offset off its surface towards the side `dir` travels into.
  glm::dvec3 offset_point(const Hit& hit, const glm::dvec3& dir) const;

  // Largest absolute vertex coordinate plus the diagonal of the vertex bounds.
  double scene_scale() const { return scene_scale_; }
  const Bvh& bvh() const { return *bvh_; }
  const SceneData& scene() const { return *scene_; }
  double build_ms() const { return build_ms_; }

 private:
  Hit make_hit(const TriangleHit& th, const glm::dvec3& dir) const;
  // The crossing set at the nearest hit `hit` of (origin, d) for a ray carrying `stack`:
  // its interface, the hit of the triangle shaded and the furthest crossing.
  Interface crossing_set(const glm::dvec3& origin, const glm::dvec3& d, const Hit& hit, const MediumStack& stack,
                         Hit* shaded, Hit* far) const;
  glm::dvec3 shade(const Hit& hit, const Hit& far, const glm::dvec3& dir, int depth, const Interface& itf,
                   RayCounts* counts) const;
  // The transmitted ray of an interface and the stack it carries.
  Ray transmitted_ray(const Hit& hit, const Hit& far, const glm::dvec3& dir, const Interface& itf,
                      MediumStack* stack) const;

  const SceneData* scene_;
  double build_ms_ = 0;  // 0 when the BVH was given
  std::shared_ptr<const Bvh> bvh_;
  double scene_scale_ = 0;
  std::shared_ptr<const Media> media_;
};

// Renders the scene's camera view with THE RULES. Throws InputError for a bad
// option (samples_per_pixel not a rung, rungs without 32 samples, negative threads).
Image render_raytrace(const SceneData& scene, const RaytraceOptions& options = {}, RaytraceStats* stats = nullptr);

}  // namespace abcube
