// GLSL sources from shaders/, embedded at build time (cmake/embed_shaders.cmake).
#pragma once

namespace abcube {

// The text of shaders/<name>, or nullptr if no such file was embedded.
const char* embedded_shader(const char* name);

}  // namespace abcube
