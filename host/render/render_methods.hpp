// The passes of each method, as the Renderer runs them (renderer.cpp): what the scene
// needs and nothing more (the plan), with the per-scene data from the SceneCache. What they
// share with --target-db's pilots (target_db.hpp), below both: method_context.hpp.
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <abcube/renderer.hpp>
#include <nlohmann/json.hpp>

#include "gl/gl_context.hpp"
#include "render/method_context.hpp"

namespace abcube {

// The GPU's raster (GlScene): flat mirrors and hard shadows exact, curved mirrors and glass
// from its cube texture; shadow maps and the environment only where the scene needs them.
Image render_gpu(MethodContext& mc);
// The cube-map methods (abuffer, zbuffer, envmap): the map is built only when something
// needs it (a reflecting or refracting material, a shadow-casting light). `only`
// (optional): the pixels to render, the others black.
Image render_map_method(MethodContext& mc, const std::vector<uint8_t>* only = nullptr);
// The hybrid method (docs/design/gpu-exact-paths.md): the GPU's exact camera pass,
// and the abuffer method on the CPU for the pixels whose samples meet a surface the GPU
// only approximates.
Image render_hybrid(MethodContext& mc);
// The exact Whitted tracer; its stats go under `key` ("raytrace" or "reference").
Image render_reference(MethodContext& mc, const char* key);
// The image's error against the exact image (traced now, or --reference-image); PSNR.
double add_reference_error(MethodContext& mc, const Image& image);

nlohmann::json gl_json(const GlContext* ctx);

// The scene as a render with `options` sees it: its camera and render settings with the
// options' overrides, checked (renderer.cpp). Shares the triangles.
SceneData scene_view(const SceneData& base, const RenderOptions& options);

}  // namespace abcube
