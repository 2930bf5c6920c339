// What Embree's own float triangles would change in the exact tracer (reference/bvh.hpp,
// "Why not Embree's float triangles"). Per scene, the rays the tracer shoots first: every
// camera sample (the 4x8 A-buffer positions of every pixel), the mirror ray from each
// camera hit (RayTracer::reflected_ray) and a shadow segment from each camera hit to each
// light. The secondary rays start 2^-14 times the scene's scale (RayTracer::scene_scale)
// along their direction, both ways: a float ray from the tracer's own offset (1e-9 of
// it) finds its own surface again, which is a float tracer's self-intersection, not the
// edge decisions measured here. Each is answered twice: by the tracer's query (Embree
// proposes, the double watertight test decides: Bvh::visible_hit, Bvh::for_each_hit) and
// by Embree's robust float triangle test alone (RTC_GEOMETRY_TYPE_TRIANGLE on the same
// float vertices, RTC_SCENE_FLAG_ROBUST, rtcIntersect1 / rtcOccluded1). Counted:
//   other_rejected  float's nearest triangle is one the double test does not hit (an edge:
//                   the ray passes within float rounding of it)
//   other_hit       float's nearest triangle is hit in double too, but is not the visible
//                   one (nearest by t in float, not by the tie rule in double)
//   float_miss      float finds nothing where the double test hits
//   float_extra     float finds a triangle where the double test hits nothing
//   shadow          segments blocked for one and not for the other
// Embree picks its instruction set at run time (--isa forces one: sse4.2, avx2, avx512):
// the counts may differ between them; the tracer's answers may not.
//
//   bench_embree_float SCENE.json... [--spp 32] [--width 0] [--isa default]
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <embree3/rtcore.h>

#include "bench_common.hpp"
#include "base/samples.hpp"
#include "reference/raytrace.hpp"
#include "scene/camera.hpp"
#include "scene/scene_load.hpp"

namespace abcube {
namespace {

struct Options {
  std::vector<std::string> scenes;
  int spp = MASK_SAMPLES;
  int width = 0;
  std::string isa = "default";
};

void add_options(BenchCommandLine& line, Options& o) {
  line.files("scenes", o.scenes, "scene files (SCENE.json...)");
  line.choice("--spp", o.spp, "camera samples per pixel: 32 (the 4x8 A-buffer positions) or 1 (centre)",
              {1, MASK_SAMPLES});
  line.number("--width", o.width, "image width in pixels, the height scaled with it; 0 = the scene's", 0, 65536);
  line.choice("--isa", o.isa, "Embree's instruction set", {"default", "sse4.2", "avx2", "avx512"});
}

// Embree's float triangles over the soup's vertices (copied: Embree reads 16 bytes per vertex).
class FloatScene {
 public:
  FloatScene(RTCDevice device, const TriangleSoup& soup) : vertices_(soup.positions) {
    vertices_.reserve(vertices_.size() + 1);
    scene_ = rtcNewScene(device);
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vertices_.data(), 0, sizeof(glm::vec3),
                               vertices_.size());
    auto* index = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(unsigned), soup.triangle_count()));
    for (size_t i = 0; i < vertices_.size(); ++i) index[i] = static_cast<unsigned>(i);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene_, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene_);
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE) throw RuntimeFailure("embree: building the float scene failed");
  }
  ~FloatScene() { rtcReleaseScene(scene_); }
  FloatScene(const FloatScene&) = delete;
  FloatScene& operator=(const FloatScene&) = delete;

  // The nearest triangle with 0 < t < tmax in float, or -1.
  long nearest(const glm::dvec3& o, const glm::dvec3& d, double tmax) const {
    RTCRayHit rh{};
    set_ray(o, d, tmax, &rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    RTCIntersectContext c;
    rtcInitIntersectContext(&c);
    rtcIntersect1(scene_, &c, &rh);
    return rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? -1 : static_cast<long>(rh.hit.primID);
  }
  bool occluded(const glm::dvec3& o, const glm::dvec3& d, double tmax) const {
    RTCRay r{};
    set_ray(o, d, tmax, &r);
    RTCIntersectContext c;
    rtcInitIntersectContext(&c);
    rtcOccluded1(scene_, &c, &r);
    return r.tfar < 0.0f;
  }

 private:
  static void set_ray(const glm::dvec3& o, const glm::dvec3& d, double tmax, RTCRay* r) {
    r->org_x = static_cast<float>(o.x);
    r->org_y = static_cast<float>(o.y);
    r->org_z = static_cast<float>(o.z);
    r->dir_x = static_cast<float>(d.x);
    r->dir_y = static_cast<float>(d.y);
    r->dir_z = static_cast<float>(d.z);
    r->tnear = 0.0f;
    r->tfar = static_cast<float>(tmax);
    r->mask = 0xffffffffu;
  }
  std::vector<glm::vec3> vertices_;
  RTCScene scene_ = nullptr;
};

struct Counts {
  long rays = 0, other_rejected = 0, other_hit = 0, float_miss = 0, float_extra = 0;
  long segments = 0, shadow = 0;
};

// One nearest-hit query both ways; returns the exact hit's presence in *exact.
void compare_nearest(const RayTracer& tracer, const FloatScene& fs, const glm::dvec3& o, const glm::dvec3& d, Counts* c,
                     Hit* exact, bool* found) {
  ++c->rays;
  *found = tracer.intersect(o, d, exact);
  const long f = fs.nearest(o, d, INFINITY);
  if (f < 0) {
    c->float_miss += *found;
    return;
  }
  if (!*found) {
    ++c->float_extra;
    return;
  }
  if (static_cast<uint32_t>(f) == exact->triangle) return;
  TriangleHit h;
  if (intersect_triangle(RayQuery(o, d), *tracer.scene().triangles, static_cast<uint32_t>(f), INFINITY, &h)) {
    ++c->other_hit;
  } else {
    ++c->other_rejected;
  }
}

int run(const Options& o) {
  const std::string config = o.isa == "default" ? "verbose=0" : "verbose=0,isa=" + o.isa;
  RTCDevice device = rtcNewDevice(config.c_str());
  if (!device) throw RuntimeFailure("embree: rtcNewDevice(" + config + ") failed");
  std::printf(
      "| scene | triangles | rays | other_rejected | other_hit | float_miss | float_extra | shadow segments | shadow "
      "|\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  Counts total;
  for (const std::string& path : o.scenes) {
    SceneData scene = load_scene(path);
    if (o.width > 0) {
      scene.camera.height = std::max(1, (scene.camera.height * o.width + scene.camera.width / 2) / scene.camera.width);
      scene.camera.width = o.width;
    }
    const RayTracer tracer(scene);
    const FloatScene fs(device, *scene.triangles);
    const CameraFrame frame = make_camera_frame(scene.camera);
    Counts c;
    for (int y = 0; y < frame.height; ++y) {
      for (int x = 0; x < frame.width; ++x) {
        for (int k = 0; k < o.spp; ++k) {
          const double sx = o.spp == 1 ? 0.5 : sample_dx(k), sy = o.spp == 1 ? 0.5 : sample_dy(k);
          const glm::dvec3 d = glm::normalize(frame.direction(x + sx, y + sy));
          Hit hit;
          bool found = false;
          compare_nearest(tracer, fs, frame.eye, d, &c, &hit, &found);
          if (!found) continue;
          const double skip = std::ldexp(tracer.scene_scale(), -14);
          const Ray r = tracer.reflected_ray(hit, d);
          Hit unused;
          compare_nearest(tracer, fs, r.origin + skip * r.dir, r.dir, &c, &unused, &found);
          for (const PointLight& light : scene.lights) {
            const glm::dvec3 to_light = light.position - hit.point;
            if (!(glm::length(to_light) > 2.0 * skip)) continue;
            const glm::dvec3 origin = hit.point + skip * glm::normalize(to_light);
            const glm::dvec3 seg = light.position - origin;
            const double dist = glm::length(seg);
            if (!(dist > 0.0)) continue;
            bool blocked = false;
            tracer.bvh().for_each_hit(RayQuery(origin, seg / dist), dist, [&](const TriangleHit&) {
              blocked = true;
              return false;
            });
            ++c.segments;
            c.shadow += blocked != fs.occluded(origin, seg / dist, dist);
          }
        }
      }
    }
    std::printf("| %s | %zu | %ld | %ld | %ld | %ld | %ld | %ld | %ld |\n", path.c_str(),
                scene.triangles->triangle_count(), c.rays, c.other_rejected, c.other_hit, c.float_miss, c.float_extra,
                c.segments, c.shadow);
    std::fflush(stdout);
    total.rays += c.rays;
    total.other_rejected += c.other_rejected;
    total.other_hit += c.other_hit;
    total.float_miss += c.float_miss;
    total.float_extra += c.float_extra;
    total.segments += c.segments;
    total.shadow += c.shadow;
  }
  std::printf("| all | | %ld | %ld | %ld | %ld | %ld | %ld | %ld |\n", total.rays, total.other_rejected,
              total.other_hit, total.float_miss, total.float_extra, total.segments, total.shadow);
  rtcReleaseDevice(device);
  return 0;
}

}  // namespace
}  // namespace abcube

int main(int argc, char** argv) {
  return abcube::bench_main<abcube::Options>(argc, argv, "bench_embree_float",
                                             "Embree's float triangles against the exact tracer's answers",
                                             abcube::add_options, abcube::run);
}
