// What the gpu method's geometry (gpu_geometry/) holds at most. The scene's memory estimate
// (scene_size.cpp) is made before that geometry is built, from these bounds, so they live
// here, below both.
#pragma once

#include <cstdint>

namespace abcube {

// Volumes a render counts at most (opaque, and translucent where any, per light): a layer
// each of an R32F array (gl_shadow_volumes.cpp); lights past them keep their cube shadow
// maps. The memory estimate counts no more.
constexpr int MAX_VOLUME_LIGHTS = 128;

// The side pairing of build_shadow_volume sorts the caps' edges (PAIRING_EDGE_BYTES each) in
// buckets by a hash, about PAIRING_BUCKET_EDGES at once, with a bucket's byte per edge.
constexpr uint64_t PAIRING_BUCKET_EDGES = uint64_t{1} << 20;
constexpr uint64_t PAIRING_EDGE_BYTES = 32;

}  // namespace abcube
