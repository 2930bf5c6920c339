// Arbitrary output variables beside the image (RenderOptions::aovs, renderer.hpp): what
// the eye ray through each pixel centre meets, from the exact tracer on the same
// triangles, whatever the method (so every method's AOVs agree by construction).
#pragma once
#include <map>
#include <string>
#include <vector>

#include "render/render_methods.hpp"

namespace abcube {

std::map<std::string, Image> render_aovs(MethodContext& mc, const std::vector<std::string>& names);

}  // namespace abcube
