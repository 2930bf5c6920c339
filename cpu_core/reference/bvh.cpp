#include "reference/bvh.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <limits>
#include <new>
#include <string>

#include <embree3/rtcore.h>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "scene/tie_rule.hpp"

namespace abcube {

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

// Embree's message for its last error, or empty.
std::string embree_error(RTCDevice device) {
  switch (rtcGetDeviceError(device)) {
    case RTC_ERROR_NONE: return "";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: throw std::bad_alloc();
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    default: return "unknown error";
  }
}

void check_embree(RTCDevice device, const char* what) {
  const std::string e = embree_error(device);
  if (!e.empty()) throw RuntimeFailure(std::string("embree: ") + what + ": " + e);
}

// Embree's build monitor (called from its worker threads now and then): false cancels the
// build, when the render that asked for it is over its time limit or a stop was requested.
bool build_may_go_on(void* deadline, double /*done*/) {
  if (stop_request().load(std::memory_order_relaxed) != 0) return false;
  return !deadline || !static_cast<const Deadline*>(deadline)->passed();
}

// Under ThreadSanitizer the tree is built on the calling thread alone: Debian's libembree3
// and libtbb are not instrumented, so TSan cannot see the synchronisation of TBB's workers
// and reports the tree's blocks (made on a worker, freed by the caller) and our bounds
// callback (run on a worker) as races (tools/sanitizers/tsan.supp). The queries, made from
// abcube's own threads, are still checked; the answers do not depend on the build threads.
#if defined(__SANITIZE_THREAD__)
#define ABCUBE_EMBREE_THREADS ",threads=1"
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define ABCUBE_EMBREE_THREADS ",threads=1"
#endif
#endif
#ifndef ABCUBE_EMBREE_THREADS
#define ABCUBE_EMBREE_THREADS ""
#endif

// One device for the process (Embree's thread pool and settings), made on first use.
// Leaves of up to 4 user primitives: a tree a fraction of the size of one with a primitive a
// leaf, and as fast to traverse.
RTCDevice embree_device() {
  struct Device {
    RTCDevice device = rtcNewDevice("verbose=0,object_accel_max_leaf_size=4" ABCUBE_EMBREE_THREADS);
    ~Device() { rtcReleaseDevice(device); }
  };
  static const Device d;
  if (!d.device) throw RuntimeFailure("embree: rtcNewDevice failed (" + embree_error(nullptr) + ")");
  return d.device;
}

// The neighbours of a finite float (the next one towards +inf / -inf), without libm.
float next_up(float f) {
  if (f == 0.0f) return std::numeric_limits<float>::denorm_min();
  uint32_t b;
  std::memcpy(&b, &f, sizeof b);
  b = f > 0.0f ? b + 1 : b - 1;
  std::memcpy(&f, &b, sizeof b);
  return f;
}
float next_down(float f) { return -next_up(-f); }

// The float nearest to x, rounded towards -inf / +inf.
float round_down(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) > x ? next_down(f) : f;
}
float round_up(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) < x ? next_up(f) : f;
}

double max3(const glm::dvec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

// Embree works in its own units: world coordinates times 2^-ilogb(M) (exact), so that
// every vertex lies within 2 of the origin whatever the scene's size (no float overflow in
// Embree's box tests, no denormals).
double embree_unit(double magnitude) { return std::ldexp(1.0, -std::ilogb(magnitude)); }

// Embree's ray for a query (docs/design/bvh.md "Exactness"): origin o_e = origin + t0 dir,
// both in Embree's units, and the direction (scaled by a power of two when its size is
// extreme), so that Embree's t is (t - t0) * scale.
struct EmbreeRay {
  double t0 = 0, scale = 1;
  float to_embree(double t) const { return t == INF ? INFINITY : round_up((t - t0) * scale); }
};

// Sets up *r and *er for the query ray and 0 < t < tmax; false when the ray cannot meet
// the cube |x|inf <= 2M that holds every triangle (or is not finite). `unit` is
// embree_unit(magnitude).
bool embree_ray(const RayQuery& q, double tmax, double magnitude, double unit, RTCRay* r, EmbreeRay* er) {
  const glm::dvec3& o = q.origin;
  const glm::dvec3& d = q.dir;
  const double reach = 2.0 * magnitude;
  double t0 = 0.0;
  if (max3(glm::abs(o)) > reach) {
    double enter = 0.0, leave = INF;
    for (int a = 0; a < 3; ++a) {
      if (d[a] == 0.0) {
        if (std::fabs(o[a]) > reach) return false;
        continue;
      }
      double tn = (-reach - o[a]) / d[a], tf = (reach - o[a]) / d[a];
      if (tn > tf) std::swap(tn, tf);
      enter = std::max(enter, tn);
      leave = std::min(leave, tf);
    }
    if (!(enter <= leave) || !(enter < tmax)) return false;
    t0 = enter;
  }
  const glm::dvec3 oe = (o + t0 * d) * unit;
  const double dmax = max3(glm::abs(d));
  if (!(dmax > 0.0) || !std::isfinite(dmax) || !std::isfinite(oe.x + oe.y + oe.z)) return false;
  // A direction between 2^-64 and 2^64 goes as it is (float holds it to 2^-24 of dmax, the
  // small coordinates included); another is brought to [1, 2) by an exact power of two.
  const int e = dmax >= 0x1p-64 && dmax <= 0x1p64 ? 0 : std::ilogb(dmax);
  const glm::dvec3 ds = e == 0 ? d : d * std::ldexp(1.0, -e);
  er->t0 = t0;
  er->scale = e == 0 ? unit : std::ldexp(unit, e);
  r->org_x = static_cast<float>(oe.x);
  r->org_y = static_cast<float>(oe.y);
  r->org_z = static_cast<float>(oe.z);
  r->dir_x = static_cast<float>(ds.x);
  r->dir_y = static_cast<float>(ds.y);
  r->dir_z = static_cast<float>(ds.z);
  r->tnear = 0.0f;
  r->tfar = er->to_embree(tmax);
  r->time = 0.0f;
  r->mask = 0xffffffffu;
  r->id = 0;
  r->flags = 0;
  return true;
}

// The state of one query: Embree passes &context back to the callbacks, so it comes first.
struct Query {
  static constexpr int KEEP = 8;
  RTCIntersectContext context;
  const TriangleSoup* soup = nullptr;
  const uint32_t* triangles = nullptr;  // Embree's primitive k is triangle triangles[k] (null: k)
  const RayQuery* ray = nullptr;
  double tmax = INF;
  EmbreeRay er;
  // visible_hit (bvh.hpp)
  double tie_bound_max = 0;
  double cull = INF;  // every hit with t < cull is found
  struct Kept {       // no initialisers: not cleared for every query
    double t;
    uint32_t triangle;
  };
  Kept kept[KEEP];
  int n_kept = 0;
  bool incomplete = false, found = false;
  TriangleHit nearest;
  // for_each_hit
  bool (*visit)(void*, const TriangleHit&) = nullptr;
  void* state = nullptr;
  bool stopped = false;

  // Sets up the context and Embree's ray *r: false when the ray can meet nothing.
  bool start(const TriangleSoup& s, const uint32_t* subset, const RayQuery& q, double t_max, double magnitude,
             double unit, RTCRay* r) {
    rtcInitIntersectContext(&context);
    soup = &s;
    triangles = subset;
    ray = &q;
    tmax = t_max;
    cull = t_max;
    return embree_ray(q, t_max, magnitude, unit, r, &er);
  }

  uint32_t triangle(unsigned prim) const { return triangles ? triangles[prim] : prim; }

  // The end of the tie window of a hit: no surface beyond it can be at its distance.
  double window_end(const TriangleHit& h) const {
    const double c = std::fabs(glm::dot(tie_normal(*soup, h.triangle), ray->dir));
    const double end = c > 0.0 ? std::nextafter(h.t + tie_bound_max / c, INF) : INF;
    return std::min(tmax, end);
  }

  void add(const TriangleHit& h) {
    if (!found || h.t < nearest.t || (h.t == nearest.t && ranks_above(*soup, h.triangle, nearest.triangle))) {
      const double end = window_end(h);
      if (found && end > cull) incomplete = true;  // hits culled before may lie in the new window
      nearest = h;
      found = true;
      cull = end;
      int w = 0;
      for (int i = 0; i < n_kept; ++i) {
        if (kept[i].t < cull) kept[w++] = kept[i];
      }
      n_kept = w;
    }
    if (n_kept < KEEP) {
      kept[n_kept++] = {h.t, h.triangle};
    } else {
      incomplete = true;
    }
  }
};

// The first of the primitives of a chunk's geometry (its user data): Embree numbers a
// geometry's primitives from 0.
uint32_t chunk_first(const void* geometry_user) { return static_cast<const Bvh::Chunk*>(geometry_user)->first; }

// Embree's callback for rtcIntersect1 (visible_hit): the double test of one candidate.
void visible_candidate(const RTCIntersectFunctionNArguments* args) {
  if (!args->valid[0]) return;  // rtcIntersect1: N = 1
  Query* q = reinterpret_cast<Query*>(args->context);
  TriangleHit h;
  if (!intersect_triangle(*q->ray, *q->soup, q->triangle(chunk_first(args->geometryUserPtr) + args->primID), q->cull,
                          &h)) {
    return;
  }
  q->add(h);
  float& tfar = RTCRayN_tfar(RTCRayHitN_RayN(args->rayhit, args->N), args->N, 0);
  tfar = std::min(tfar, q->er.to_embree(q->cull));  // never widened: a wider window is the second traversal's
}

// Embree's callback for rtcOccluded1 (for_each_hit): the double test of one candidate;
// tfar = -inf ends the traversal (Embree's "occluded").
void visit_candidate(const RTCOccludedFunctionNArguments* args) {
  if (!args->valid[0]) return;  // rtcOccluded1: N = 1
  Query* q = reinterpret_cast<Query*>(args->context);
  if (q->stopped) return;
  TriangleHit h;
  if (!intersect_triangle(*q->ray, *q->soup, q->triangle(chunk_first(args->geometryUserPtr) + args->primID), q->tmax,
                          &h)) {
    return;
  }
  if (q->visit(q->state, h)) return;
  q->stopped = true;
  RTCRayN_tfar(args->ray, args->N, 0) = -INFINITY;
}

// A primitive's box, in Embree's units: the triangle's float bounds widened by BOX_PAD M,
// rounded outwards.
void triangle_bounds(const RTCBoundsFunctionArguments* args) {
  const Bvh::Chunk& chunk = *static_cast<const Bvh::Chunk*>(args->geometryUserPtr);
  const Bvh* bvh = chunk.bvh;
  const glm::vec3* p = &bvh->soup().positions[3 * static_cast<size_t>(bvh->triangle(chunk.first + args->primID))];
  const double unit = embree_unit(bvh->magnitude());  // Bvh::unit_
  const glm::dvec3 lo = glm::dvec3(glm::min(p[0], glm::min(p[1], p[2]))) * unit;
  const glm::dvec3 hi = glm::dvec3(glm::max(p[0], glm::max(p[1], p[2]))) * unit;
  const double pad = Bvh::BOX_PAD * bvh->magnitude() * unit;
  RTCBounds* b = args->bounds_o;
  if (!std::isfinite(lo.x + lo.y + lo.z + hi.x + hi.y + hi.z)) {  // never hit: an empty box
    b->lower_x = b->lower_y = b->lower_z = INFINITY;
    b->upper_x = b->upper_y = b->upper_z = -INFINITY;
    return;
  }
  b->lower_x = round_down(lo.x - pad);
  b->lower_y = round_down(lo.y - pad);
  b->lower_z = round_down(lo.z - pad);
  b->upper_x = round_up(hi.x + pad);
  b->upper_y = round_up(hi.y + pad);
  b->upper_z = round_up(hi.z + pad);
}

}  // namespace

Bvh::Bvh(const TriangleSoup& soup, uint32_t build_chunk) : soup_(&soup) { build(build_chunk); }

Bvh::Bvh(const TriangleSoup& soup, std::vector<uint32_t> triangles, uint32_t build_chunk)
    : soup_(&soup), all_(false), triangles_(std::move(triangles)) {
  for (const uint32_t t : triangles_) ABCUBE_CHECK(t < soup.triangle_count(), "triangle index out of range");
  build(build_chunk);
}

void Bvh::build(uint32_t build_chunk) {
  ABCUBE_CHECK(build_chunk > 0, "build chunk");
  const TriangleSoup& soup = *soup_;
  ABCUBE_CHECK(soup.positions.size() == 3 * soup.triangle_count(), "positions must hold 3 vertices per triangle");
  ABCUBE_CHECK(soup.triangle_count() < UINT32_MAX / 3, "too many triangles for 32-bit indices");
  const uint32_t n = static_cast<uint32_t>(triangle_count());
  double magnitude = 0.0;
  for (uint32_t k = 0; k < n; ++k) magnitude = std::max(magnitude, triangle_magnitude(soup, triangle(k)));
  tie_bound_max_ = TIE_RELATIVE * magnitude;
  // M over the finite coordinates (the loader drops triangles with others; a hand-made
  // soup's are given empty boxes: never hit).
  for (uint32_t k = 0; k < n; ++k) {
    for (size_t v = 0; v < 3; ++v) {
      const glm::vec3& p = soup.positions[3 * static_cast<size_t>(triangle(k)) + v];
      for (int c = 0; c < 3; ++c) {
        if (std::isfinite(p[c])) magnitude_ = std::max(magnitude_, static_cast<double>(std::fabs(p[c])));
      }
    }
  }
  if (n == 0 || !(magnitude_ > 0.0)) return;  // nothing to hit (all vertices at the origin: all degenerate)
  unit_ = embree_unit(magnitude_);
  const RTCDevice device = embree_device();
  const uint32_t chunks = static_cast<uint32_t>((uint64_t{n} + build_chunk - 1) / build_chunk);
  chunks_.clear();
  chunks_.reserve(chunks);  // never moved: each is its geometry's user data
  for (uint32_t c = 0; c < chunks; ++c) chunks_.push_back({this, c * build_chunk});
  const auto new_scene = [&] {
    RTCScene scene = rtcNewScene(device);
    check_embree(device, "rtcNewScene");
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_COMPACT);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_MEDIUM);
    rtcSetSceneProgressMonitorFunction(scene, build_may_go_on, const_cast<Deadline*>(current_deadline()));
    return scene;
  };
  const auto commit = [&](RTCScene scene, RTCScene also_release) {
    rtcCommitScene(scene);
    const std::string e = embree_error(device);
    if (e.empty()) return;
    rtcReleaseScene(scene);
    if (also_release) rtcReleaseScene(also_release);
    check_deadline();  // a cancelled build: RenderTimeout or Interrupted
    throw RuntimeFailure("embree: building the tree over " + std::to_string(n) + " triangles: " + e);
  };
  // Chunk c's triangles as a user geometry of `scene`.
  const auto attach_chunk = [&](RTCScene scene, uint32_t c) {
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geometry, std::min(build_chunk, n - chunks_[c].first));
    rtcSetGeometryUserData(geometry, &chunks_[c]);
    rtcSetGeometryBoundsFunction(geometry, triangle_bounds, nullptr);
    rtcSetGeometryIntersectFunction(geometry, visible_candidate);
    rtcSetGeometryOccludedFunction(geometry, visit_candidate);
    rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_MEDIUM);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene, geometry);
    rtcReleaseGeometry(geometry);
  };
  RTCScene scene = new_scene();
  if (chunks == 1) {
    attach_chunk(scene, 0);
  } else {
    // Each chunk built on its own, then held by an identity instance (exact in float: x * 1
    // + y * 0 + z * 0 + 0 = x) of the top scene.
    const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    for (uint32_t c = 0; c < chunks; ++c) {
      RTCScene part = new_scene();
      attach_chunk(part, c);
      commit(part, scene);
      RTCGeometry instance = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(instance, part);
      rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
      rtcCommitGeometry(instance);
      rtcAttachGeometry(scene, instance);
      rtcReleaseGeometry(instance);
      rtcReleaseScene(part);  // held by its instance
    }
  }
  commit(scene, nullptr);
  scene_ = scene;
}

Bvh::~Bvh() {
  if (scene_) rtcReleaseScene(scene_);
}

bool Bvh::visible_hit(const RayQuery& ray, double tmax, TriangleHit* hit) const {
  if (!scene_) return false;
  Query q;
  RTCRayHit rh;
  if (!q.start(*soup_, all_ ? nullptr : triangles_.data(), ray, tmax, magnitude_, unit_, &rh.ray)) return false;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  q.tie_bound_max = tie_bound_max_;
  rtcIntersect1(scene_, &q.context, &rh);
  if (!q.found) return false;
  const TriangleSoup& soup = *soup_;
  const SurfaceAt near_at{q.nearest.triangle, q.nearest.t};
  TriangleHit best = q.nearest;
  const auto consider = [&](const TriangleHit& h) {
    if (ranks_above(soup, h.triangle, best.triangle) && same_distance(soup, ray.dir, near_at, {h.triangle, h.t}))
      best = h;
    return true;
  };
  if (q.incomplete) {
    for_each_hit(ray, q.cull, consider);  // the nearest hit's whole window, again
  } else {
    for (int i = 0; i < q.n_kept; ++i) {  // a kept hit that wins is tested again: the same hit
      const Query::Kept& k = q.kept[i];
      TriangleHit h;
      if (ranks_above(soup, k.triangle, best.triangle) && same_distance(soup, ray.dir, near_at, {k.triangle, k.t}) &&
          intersect_triangle(ray, soup, k.triangle, INF, &h)) {
        best = h;
      }
    }
  }
  *hit = best;
  return true;
}

void Bvh::visit_hits(const RayQuery& ray, double tmax, VisitFn visit, void* state) const {
  if (!scene_) return;
  Query q;
  RTCRay r;
  if (!q.start(*soup_, all_ ? nullptr : triangles_.data(), ray, tmax, magnitude_, unit_, &r)) return;
  q.visit = visit;
  q.state = state;
  rtcOccluded1(scene_, &q.context, &r);
}

}  // namespace abcube
