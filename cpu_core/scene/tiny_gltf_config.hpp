// tinygltf as abcube builds it: every translation unit that includes tiny_gltf.h must see
// the same options (the TinyGLTF class's members depend on them). No stb_image: images are
// never decoded (scene_gltf.cpp keeps their encoded bytes for the samplers); external image
// files are not opened by tinygltf (scene_gltf.cpp resolves and confines their paths).
#pragma once
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>
