// The gpu_abuffer method: the abuffer method with its camera's and cube's A-buffers built by
// GL compute shaders (gl/gl_abuffer.hpp), the same lists as the CPU core's; the searches
// walk on the GPU too where --search-on says (the DEFERRED SEARCHES over gl_cube_scan.hpp),
// and the resolve is planned there where --resolve-on says (THE RESOLVE PLAN,
// gl_resolve_plan.hpp); the shading runs on the CPU. Its options are abuffer's, --search-on
// and --resolve-on.
#include <memory>

#include "render/method.hpp"
#include "render/render_methods.hpp"

namespace abcube {

std::unique_ptr<RenderMethod> make_map_method(MapVariant variant);  // map_methods.cpp

namespace {

class GpuABufferMethod : public RenderMethod {
 public:
  GpuABufferMethod() : abuffer_(make_map_method(MapVariant::abuffer)) {}
  std::string name() const override { return "gpu_abuffer"; }
  std::string summary() const override {
    return "abuffer with its A-buffers built on the GPU by compute shaders (the same lists), its searches too by "
           "--search-on";
  }
  std::vector<std::string> reads() const override {
    std::vector<std::string> keys = abuffer_->reads();
    keys.push_back("search_on");
    keys.push_back("resolve_on");
    return keys;
  }
  void read_options(const RenderOptions& options, const SceneData& view, RenderRequest* request) const override {
    abuffer_->read_options(options, view, request);
    request->abuffers_on_gl = true;
    read_search_on(options, request);
    read_resolve_on(options, request);
  }
  bool needs_gl() const override { return true; }
  Image render(MethodContext& mc) const override {
    Image image = render_map_method(mc);
    mc.stats["plan"]["abuffers_built_on"] = "gpu";  // as hybrid's "cpu" object says it
    return image;
  }

 private:
  std::unique_ptr<RenderMethod> abuffer_;
};

}  // namespace

std::unique_ptr<RenderMethod> make_gpu_abuffer_method() { return std::make_unique<GpuABufferMethod>(); }

}  // namespace abcube
