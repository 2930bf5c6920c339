#include "render/aovs.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/parallel.hpp"
#include "reference/raytrace.hpp"
#include "scene/camera.hpp"

namespace abcube {

std::map<std::string, Image> render_aovs(MethodContext& mc, const std::vector<std::string>& names) {
  const RayTracer tracer(mc.scene, mc.cache.bvh());
  const CameraFrame frame = make_camera_frame(mc.scene.camera);
  const float inf = std::numeric_limits<float>::infinity();
  Image distance(frame.width, frame.height, 1, inf), normal(frame.width, frame.height, 3, 0.f),
      object(frame.width, frame.height, 1, -1.f), shadowed(frame.width, frame.height, 1, 0.f);
  const bool want_shadowed = std::find(names.begin(), names.end(), "shadowed") != names.end();
  // One eye ray per pixel centre: the first surface, its distance, normal and object.
  parallel_for(static_cast<size_t>(frame.height), thread_count(mc.request.threads, static_cast<size_t>(frame.height)),
               [&](size_t row, int) {
                 const int y = static_cast<int>(row);
                 for (int x = 0; x < frame.width; ++x) {
                   const glm::dvec3 dir = glm::normalize(frame.direction(x + 0.5, y + 0.5));
                   Hit hit;
                   if (!tracer.intersect(frame.eye, dir, &hit)) continue;
                   distance.at(x, y)[0] = static_cast<float>(glm::length(hit.point - frame.eye));
                   glm::dvec3 n = hit.shading_normal;
                   if (glm::dot(n, dir) > 0) n = -n;  // facing the camera
                   normal.set_rgb(x, y, glm::vec3(n));
                   object.at(x, y)[0] = static_cast<float>(hit.object_id);
                   if (!want_shadowed || mc.scene.lights.empty()) continue;
                   // The share of the lights whose light the surface does not get whole (a
                   // blocker on the way, opaque or not).
                   int blocked = 0;
                   for (const PointLight& light : mc.scene.lights) {
                     const glm::dvec3 v = tracer.light_visibility(hit, light, nullptr);
                     blocked += std::min(v.x, std::min(v.y, v.z)) < 1.0;
                   }
                   shadowed.at(x, y)[0] = static_cast<float>(blocked) / static_cast<float>(mc.scene.lights.size());
                 }
               });
  std::map<std::string, Image> out;
  for (const std::string& name : names) {
    if (name == "distance") out[name] = distance;
    if (name == "normal") out[name] = normal;
    if (name == "object_id") out[name] = object;
    if (name == "shadowed") out[name] = shadowed;
    if (name == "fallback")
      out[name] = mc.fallback && mc.fallback->width > 0 ? *mc.fallback : Image(frame.width, frame.height, 1, 0.f);
  }
  return out;
}

}  // namespace abcube
