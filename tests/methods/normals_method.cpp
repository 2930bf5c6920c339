// A render method added from outside the library, in this one file: what a user who adds a
// method writes (docs/design/overview.md "Adding a method"). "normals" shows the shading
// normal of the first surface each camera sample meets, as colour 0.5 + 0.5 n (black where
// none), averaged over the first `samples` rungs of the sample ladder: it reads one
// per-method option of the table, samples, which the raytrace method reads too.
//
// Linked into a program (tests/methods/CMakeLists.txt: the abcube CLI's main, and the Python
// module), the registration line below adds it to every door: --method normals, a scene's
// "render": {"method": "normals"}, a batch job's "method", and method="normals" in Python.
#include <memory>

#include "base/parallel.hpp"
#include "base/samples.hpp"
#include "reference/raytrace.hpp"
#include "render/method.hpp"
#include "scene/camera.hpp"

namespace {

class NormalsMethod : public abcube::RenderMethod {
 public:
  std::string name() const override { return "normals"; }
  std::string summary() const override {
    return "the first surface's shading normal, as colour (a test of the registry)";
  }
  std::vector<std::string> reads() const override { return {"samples"}; }
  abcube::Image render(abcube::MethodContext& mc) const override {
    const abcube::SceneData& scene = mc.scene;
    const abcube::RayTracer tracer(scene, mc.cache.bvh());
    const abcube::CameraFrame frame = abcube::make_camera_frame(scene.camera);
    const int samples = scene.render.samples;  // the scene's, or --samples
    abcube::Image image(scene.camera.width, scene.camera.height, 3);
    const size_t rows = static_cast<size_t>(scene.camera.height);
    abcube::parallel_for(rows, abcube::thread_count(mc.request.threads, rows), [&](size_t row, int) {
      const int y = static_cast<int>(row);
      for (int x = 0; x < scene.camera.width; ++x) {
        glm::dvec3 sum(0.0);
        for (int s = 0; s < samples; ++s) {
          const int k = abcube::SAMPLE_LADDER[s];
          const double dx = samples == 1 ? 0.5 : abcube::sample_dx(k), dy = samples == 1 ? 0.5 : abcube::sample_dy(k);
          const glm::dvec3 dir = frame.direction(x + dx, y + dy);
          abcube::Hit hit;
          if (!tracer.intersect(frame.eye, dir, &hit)) continue;
          const glm::dvec3 n = glm::dot(hit.shading_normal, dir) > 0 ? -hit.shading_normal : hit.shading_normal;
          sum += 0.5 + 0.5 * n;
        }
        image.set_rgb(x, y, glm::vec3(sum / double(samples)));
      }
    });
    mc.stats["plan"]["passes"] = {"normals"};
    mc.stats["counts"]["camera_samples_per_pixel"] = samples;
    return image;
  }
};

// The one registration line.
const bool registered = abcube::register_method(std::make_unique<NormalsMethod>());

}  // namespace
