// The one translation unit that holds tinygltf's implementation (Debian's libtinygltf-dev
// is the header; its shared library would bring stb_image), with the options of
// tiny_gltf_config.hpp. Files are read through scene_gltf.cpp's callbacks only.
#define TINYGLTF_IMPLEMENTATION
#include "scene/tiny_gltf_config.hpp"
