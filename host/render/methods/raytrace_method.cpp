// The raytrace method: the exact Whitted tracer on the same triangles (the reference of the
// other methods), at its rung of the sample ladder, or at the rung --target-db picks.
#include <memory>

#include "render/method.hpp"
#include "render/render_methods.hpp"

namespace abcube {

namespace {

class RaytraceMethod : public RenderMethod {
 public:
  std::string name() const override { return "raytrace"; }
  std::string summary() const override {
    return "the exact Whitted tracer: the reference, or the rival at fewer samples a pixel";
  }
  std::vector<std::string> reads() const override { return {"target_db", "samples"}; }
  Image render(MethodContext& mc) const override {
    Image image = render_reference(mc, "raytrace");
    mc.stats["plan"]["passes"] = {"raytrace"};
    mc.stats["plan"]["skipped"] = {{{"pass", "gl"}, {"why", "the exact tracer needs no GL"}}};
    mc.record.gl_renderer = "none (the tracer is CPU only)";
    return image;
  }
};

}  // namespace

std::unique_ptr<RenderMethod> make_raytrace_method() { return std::make_unique<RaytraceMethod>(); }

}  // namespace abcube
