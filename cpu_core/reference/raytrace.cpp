#include "reference/raytrace.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "scene/camera.hpp"
#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/samples.hpp"
#include "material/shading.hpp"
#include "base/timer.hpp"

namespace abcube {

namespace {

std::shared_ptr<const Bvh> timed_build(const TriangleSoup& soup, std::shared_ptr<const Bvh> given, double* ms) {
  if (given) return given;
  const Clock::time_point start = Clock::now();
  auto bvh = std::make_shared<const Bvh>(soup);
  *ms = ms_since(start);
  return bvh;
}

glm::dvec3 vertex(const TriangleSoup& soup, uint32_t tri, int k) {
  return glm::dvec3(soup.positions[3 * static_cast<size_t>(tri) + k]);
}

// One surface crossing of a shadow segment that lets some light through.
struct Crossing {
  double t;
  uint32_t triangle, object;
  bool front;
  glm::dvec3 transmittance;
};

}  // namespace

RayTracer::RayTracer(const SceneData& scene, std::shared_ptr<const Bvh> bvh)
    : scene_(&scene),
      bvh_(timed_build(*scene.triangles, std::move(bvh), &build_ms_)),
      scene_scale_(abcube::scene_scale(scene)),
      media_(std::make_shared<const Media>(scene)) {
  ABCUBE_CHECK(scene.triangles->normals.size() == scene.triangles->positions.size(), "one normal per triangle vertex");
  ABCUBE_CHECK(scene.triangles->material_id.size() == scene.triangles->triangle_count(),
               "one material id per triangle");
  for (uint32_t id : scene.triangles->material_id) {
    ABCUBE_CHECK(id < scene.materials.size(), "material id " + std::to_string(id) + " out of range");
  }
}

Hit RayTracer::make_hit(const TriangleHit& th, const glm::dvec3& dir) const {
  const TriangleSoup& soup = *scene_->triangles;
  const glm::dvec3 a = vertex(soup, th.triangle, 0);
  const glm::dvec3 b = vertex(soup, th.triangle, 1);
  const glm::dvec3 c = vertex(soup, th.triangle, 2);
  Hit h;
  h.t = th.t;
  h.triangle = th.triangle;
  h.barycentric = glm::dvec3(th.b0, th.b1, th.b2);
  h.point = th.b0 * a + th.b1 * b + th.b2 * c;
  const glm::dvec3 ng = glm::cross(b - a, c - a);
  const double ng_len = glm::length(ng);
  h.geometric_normal = ng_len > 0.0 ? ng / ng_len : -glm::normalize(dir);
  const size_t n0 = 3 * static_cast<size_t>(th.triangle);
  const glm::dvec3 ns = th.b0 * glm::dvec3(soup.normals[n0]) + th.b1 * glm::dvec3(soup.normals[n0 + 1]) +
                        th.b2 * glm::dvec3(soup.normals[n0 + 2]);
  const double ns_len = glm::length(ns);
  h.shading_normal = ns_len > 0.0 ? ns / ns_len : h.geometric_normal;
  h.object_id = soup.object_id[th.triangle];
  h.material_id = soup.material_id[th.triangle];
  h.front_face = glm::dot(h.geometric_normal, dir) < 0.0;
  return h;
}

bool RayTracer::intersect(const glm::dvec3& origin, const glm::dvec3& dir, double tmax, Hit* hit) const {
  ABCUBE_CHECK(dir != glm::dvec3(0.0), "ray direction must not be zero");
  TriangleHit th;
  if (!bvh_->visible_hit(RayQuery(origin, dir), tmax, &th)) return false;  // tie_rule.hpp
  *hit = make_hit(th, dir);
  return true;
}

bool RayTracer::intersect(const glm::dvec3& origin, const glm::dvec3& dir, Hit* hit) const {
  return intersect(origin, dir, std::numeric_limits<double>::infinity(), hit);
}

glm::dvec3 RayTracer::offset_point(const Hit& hit, const glm::dvec3& dir) const {
  return offset_origin(hit.point, hit.geometric_normal, dir, self_intersection_offset(hit.point, scene_scale_));
}

Ray RayTracer::reflected_ray(const Hit& hit, const glm::dvec3& dir) const {
  const glm::dvec3 r = glm::normalize(reflect_dir(dir, hit.shading_normal));
  return {offset_point(hit, r), r};
}

Ray RayTracer::transmitted_ray(const Hit& hit, const glm::dvec3& dir, bool* total_internal_reflection) const {
  const Material& m = scene_->materials[hit.material_id];
  const Transmission tr = transmission(dir, hit.geometric_normal, hit.shading_normal, m.ior);
  if (total_internal_reflection) *total_internal_reflection = tr.total_internal_reflection;
  const glm::dvec3 t = glm::normalize(tr.dir);
  return {offset_point(hit, t), t};
}

Ray RayTracer::continued_ray(const Hit& hit, const glm::dvec3& dir) const { return {offset_point(hit, dir), dir}; }

glm::dvec3 RayTracer::light_visibility(const Hit& hit, const PointLight& light, RayCounts* counts) const {
  if (!light.cast_shadows) return glm::dvec3(1.0);
  const glm::dvec3 origin = offset_point(hit, light.position - hit.point);
  const glm::dvec3 seg = light.position - origin;
  const double dist = glm::length(seg);
  if (!(dist > 0.0)) return glm::dvec3(1.0);
  const glm::dvec3 dir = seg / dist;
  if (counts) ++counts->shadow;
  const TriangleSoup& soup = *scene_->triangles;
  bool opaque = false;
  std::vector<Crossing> crossings;
  bvh_->for_each_hit(RayQuery(origin, dir), dist, [&](const TriangleHit& th) {
    if (plane_holds_light(soup, th.triangle, light.position)) return true;
    const glm::dvec3 tr = blocker_transmittance(scene_->materials[soup.material_id[th.triangle]]);
    if (tr == glm::dvec3(0.0)) {
      opaque = true;
      return false;
    }
    const glm::dvec3 a = vertex(soup, th.triangle, 0);
    const bool front =
        glm::dot(glm::cross(vertex(soup, th.triangle, 1) - a, vertex(soup, th.triangle, 2) - a), dir) < 0.0;
    crossings.push_back({th.t, th.triangle, soup.object_id[th.triangle], front, tr});
    return true;
  });
  if (opaque) return glm::dvec3(0.0);
  // Product in order along the segment; a crossing through a shared edge counts once.
  std::sort(crossings.begin(), crossings.end(),
            [](const Crossing& x, const Crossing& y) { return x.t != y.t ? x.t < y.t : x.triangle < y.triangle; });
  glm::dvec3 s(1.0);
  for (size_t i = 0; i < crossings.size(); ++i) {
    const Crossing& c = crossings[i];
    if (i > 0) {
      const Crossing& p = crossings[i - 1];
      const double tol = self_intersection_offset(origin + c.t * dir, scene_scale_);
      if (p.object == c.object && p.front == c.front && c.t - p.t <= tol) continue;
    }
    s *= c.transmittance;
  }
  return s;
}

Interface RayTracer::crossing_set(const glm::dvec3& origin, const glm::dvec3& d, const Hit& hit,
                                  const MediumStack& stack, Hit* shaded, Hit* far) const {
  *shaded = hit;
  *far = hit;
  const MediumCrossing first{hit.triangle, !hit.front_face, hit.t};
  if (!media_->is_medium(hit.triangle)) return media_->resolve(stack, &first, 1);
  // Every surface crossed within the coincident tolerance of the nearest hit (media.hpp), on
  // both sides: the nearest hit's t and a coincident triangle's may differ by rounding
  // either way (a face shared by two boxes can come out a rounding below it).
  const double tol = media_->tolerance(hit.point);
  std::vector<TriangleHit> hits;
  bvh_->for_each_hit(RayQuery(origin, d), hit.t + tol, [&](const TriangleHit& th) {
    if (th.triangle != hit.triangle && th.t >= hit.t - tol) hits.push_back(th);
    return true;
  });
  if (hits.empty()) return media_->resolve(stack, &first, 1);
  std::sort(hits.begin(), hits.end(), [](const TriangleHit& a, const TriangleHit& b) {  // not in Embree's order
    return a.t != b.t ? a.t < b.t : a.triangle < b.triangle;
  });
  std::vector<MediumCrossing> set{first};
  std::vector<Hit> set_hits{hit};
  for (const TriangleHit& th : hits) {
    set_hits.push_back(make_hit(th, d));
    set.push_back({th.triangle, !set_hits.back().front_face, th.t});
  }
  const Interface itf = media_->resolve(stack, set.data(), set.size());
  for (const Hit& h : set_hits) {
    if (h.triangle == itf.triangle) *shaded = h;
    if (h.t > far->t || (h.t == far->t && h.triangle > far->triangle)) *far = h;
  }
  return itf;
}

Ray RayTracer::transmitted_ray(const Hit& hit, const Hit& far, const glm::dvec3& dir, const Interface& itf,
                               MediumStack* stack) const {
  const Transmission tr = transmission_between(dir, hit.geometric_normal, hit.shading_normal, itf.n_from, itf.n_to);
  const glm::dvec3 t = glm::normalize(tr.dir);
  // Total internal reflection: the ray stays on the incoming side, in the media before.
  *stack = tr.total_internal_reflection ? itf.before : itf.after;
  return {offset_point(tr.total_internal_reflection ? hit : far, t), t};
}

glm::dvec3 RayTracer::shade(const Hit& hit, const glm::dvec3& dir, int depth, RayCounts* counts) const {
  const MediumCrossing c{hit.triangle, !hit.front_face, hit.t};
  return shade(hit, hit, dir, depth, media_->resolve(MediumStack{}, &c, 1), counts);
}

glm::dvec3 RayTracer::shade(const Hit& hit, const Hit& far, const glm::dvec3& dir, int depth, const Interface& itf,
                            RayCounts* counts) const {
  RayCounts unused;
  if (!counts) counts = &unused;
  const Material& m = scene_->materials[hit.material_id];
  const int max_depth = scene_->render.max_depth;
  // Coverage transparency: the surface covers `opacity` of the ray (thesis 5.2.1).
  glm::dvec3 behind(0.0);
  if (m.opacity < 1.0) {
    const Ray r = continued_ray(far, dir);
    ++counts->secondary;
    behind = trace(r.origin, r.dir, depth, itf.after, counts);
    if (m.opacity <= 0.0) return behind;
  }
  // Local Phong term with shadows (shading.hpp; thesis ch. 6).
  const glm::dvec3 v = -dir;
  const glm::dvec3 n = face_forward(hit.shading_normal, v);
  const glm::dvec3 od = diffuse_color(*scene_, hit.triangle, hit.barycentric);
  glm::dvec3 c = phong_ambient(m, scene_->ambient, od);
  for (const PointLight& light : scene_->lights) {
    const glm::dvec3 to_light = light.position - hit.point;
    if (to_light == glm::dvec3(0.0)) continue;  // a light on the surface has no direction
    const glm::dvec3 lit = phong_light(m, n, v, glm::normalize(to_light), light.color, od);
    if (lit == glm::dvec3(0.0)) continue;
    c += lit * light_visibility(hit, light, counts);
  }
  // Whitted 1980: mirror and refracted rays, to the depth limit (weights: rule "fresnel").
  const SecondaryWeights w = secondary_weights(
      m, scene_->render.fresnel, dir,
      transmission_between(dir, hit.geometric_normal, hit.shading_normal, itf.n_from, itf.n_to), hit.geometric_normal);
  if (depth < max_depth && w.reflect > 0.0) {
    const Ray r = reflected_ray(hit, dir);
    ++counts->secondary;
    c += w.reflect * trace(r.origin, r.dir, depth + 1, itf.before, counts);
  }
  if (depth < max_depth && w.transmit > 0.0) {
    MediumStack stack;
    const Ray r = transmitted_ray(hit, far, dir, itf, &stack);
    ++counts->secondary;
    c += w.transmit * trace(r.origin, r.dir, depth + 1, stack, counts);
  }
  return m.opacity < 1.0 ? blend_coverage(m.opacity, c, behind) : c;
}

glm::dvec3 RayTracer::trace(const glm::dvec3& origin, const glm::dvec3& dir, int depth, RayCounts* counts) const {
  return trace(origin, dir, depth, MediumStack{}, counts);
}

glm::dvec3 RayTracer::trace(const glm::dvec3& origin, const glm::dvec3& dir, int depth, const MediumStack& stack,
                            RayCounts* counts) const {
  const glm::dvec3 d = glm::normalize(dir);
  Hit hit;
  if (!intersect(origin, d, &hit)) return scene_->background;
  Hit shaded, far;
  const Interface itf = crossing_set(origin, d, hit, stack, &shaded, &far);
  if (itf.pass) {  // no interface: the same ray goes on from past the set
    if (itf.after.passes > MEDIA_MAX_PASSES) return scene_->background;
    return trace(offset_point(far, d), d, depth, itf.after, counts);
  }
  return shade(shaded, far, d, depth, itf, counts);
}

std::vector<Ray> RayTracer::transmitted_path(const glm::dvec3& origin, const glm::dvec3& dir, int max_rays) const {
  std::vector<Ray> path;
  Ray ray{origin, glm::normalize(dir)};
  MediumStack stack;
  while (static_cast<int>(path.size()) < max_rays) {
    Hit hit;
    if (!intersect(ray.origin, ray.dir, &hit)) break;
    Hit shaded, far;
    const Interface itf = crossing_set(ray.origin, ray.dir, hit, stack, &shaded, &far);
    if (itf.pass) {
      if (itf.after.passes > MEDIA_MAX_PASSES) break;
      ray = {offset_point(far, ray.dir), ray.dir};
      stack = itf.after;
      continue;
    }
    if (!(scene_->materials[shaded.material_id].transmit > 0.0)) break;
    ray = transmitted_ray(shaded, far, ray.dir, itf, &stack);
    path.push_back(ray);
  }
  return path;
}

namespace {

// One row of the image: every pixel the mean of its camera samples (box filter). At 32
// samples they are summed in their own order, at a lower rung in the ladder's; the rungs of a
// pilot are the ladder's prefixes of the same colours, summed as a render at that rung sums.
void render_row(const RayTracer& tracer, const CameraFrame& frame, int spp, int y, Image* image, RayCounts* counts,
                const std::vector<uint8_t>* only, std::array<Image, LOWER_RUNGS>* rungs) {
  glm::dvec3 colour[MASK_SAMPLES];
  for (int x = 0; x < frame.width; ++x) {
    if (only && !(*only)[static_cast<size_t>(y) * static_cast<size_t>(frame.width) + static_cast<size_t>(x)]) continue;
    const auto sample = [&](double sx, double sy) {
      return tracer.trace(frame.eye, frame.direction(x + sx, y + sy), 0, counts);
    };
    glm::dvec3 sum(0.0);
    if (spp == 1) {
      sum = sample(0.5, 0.5);
    } else if (spp < MASK_SAMPLES) {
      for (int i = 0; i < spp; ++i) sum += sample(sample_dx(SAMPLE_LADDER[i]), sample_dy(SAMPLE_LADDER[i]));
    } else {
      for (int k = 0; k < MASK_SAMPLES; ++k) sum += colour[k] = sample(sample_dx(k), sample_dy(k));
    }
    counts->primary += static_cast<uint64_t>(spp);
    image->set_rgb(x, y, glm::vec3(sum / static_cast<double>(spp)));
    if (!rungs) continue;
    (*rungs)[0].set_rgb(x, y, glm::vec3(sample(0.5, 0.5)));
    ++counts->primary;
    glm::dvec3 prefix(0.0);
    for (int i = 0, rung = 1; rung < LOWER_RUNGS; ++rung) {
      const int s = 1 << rung;
      for (; i < s; ++i) prefix += colour[SAMPLE_LADDER[i]];
      (*rungs)[static_cast<size_t>(rung)].set_rgb(x, y, glm::vec3(prefix / static_cast<double>(s)));
    }
  }
}

}  // namespace

Image render_raytrace(const SceneData& scene, const RaytraceOptions& options, RaytraceStats* stats) {
  if (!is_sample_rung(options.samples_per_pixel)) {
    throw InputError("raytrace: samples per pixel must be 1, 2, 4, 8, 16 or 32, got " +
                     std::to_string(options.samples_per_pixel));
  }
  if (options.rungs && options.samples_per_pixel != MASK_SAMPLES) {
    throw InputError("raytrace: the ladder's rungs need 32 samples a pixel");
  }
  if (options.threads < 0) throw InputError("raytrace: threads must be >= 0, got " + std::to_string(options.threads));
  ABCUBE_CHECK(!options.only || options.only->size() ==
                                    static_cast<size_t>(scene.camera.width) * static_cast<size_t>(scene.camera.height),
               "the pixel mask does not match the image");
  const RayTracer tracer(scene, options.bvh);
  const CameraFrame frame = make_camera_frame(scene.camera);
  Image image(frame.width, frame.height, 3);
  if (options.rungs) {
    for (Image& rung : *options.rungs) rung = Image(frame.width, frame.height, 3);
  }
  const int threads = thread_count(options.threads, static_cast<size_t>(frame.height));

  const Clock::time_point start = Clock::now();
  std::atomic<int> rows_done{0};
  std::vector<RayCounts> counts(static_cast<size_t>(threads));
  double reported = 0;  // written by worker 0 only, which is the calling thread
  parallel_for(static_cast<size_t>(frame.height), threads, [&](size_t row, int worker) {
    render_row(tracer, frame, options.samples_per_pixel, static_cast<int>(row), &image,
               &counts[static_cast<size_t>(worker)], options.only, options.rungs);
    const int done = ++rows_done;
    if (worker == 0 && options.progress) options.progress(reported = static_cast<double>(done) / frame.height);
  });
  if (options.progress && reported < 1.0) options.progress(1.0);  // the other threads did the last rows

  if (stats) {
    *stats = RaytraceStats{};
    for (const RayCounts& c : counts) {
      stats->primary_rays += c.primary;
      stats->secondary_rays += c.secondary;
      stats->shadow_rays += c.shadow;
    }
    stats->build_ms = tracer.build_ms();
    stats->trace_ms = ms_since(start);
    stats->triangles = scene.triangles->triangle_count();
    stats->threads = threads;
  }
  return image;
}

}  // namespace abcube
