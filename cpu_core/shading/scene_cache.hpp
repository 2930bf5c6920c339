// Per-scene data that every render of one scene reuses, whatever its camera, method or
// settings: the mesh's edge adjacency (the searches' MESH REFINEMENT), the lens fits of
// closed transparent objects (lens.hpp), and the exact tracer's BVH. Each is built on its
// first use, once, and kept for the cache's life. Depends on the triangles, materials and
// objects only, never on the camera or the render settings.
//
// Thread safety: every member may be called from several threads at once (each piece is
// built under std::call_once; the others wait for it).
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "reference/bvh.hpp"
#include "scene/scene_data.hpp"
#include "search/lens.hpp"
#include "search/search.hpp"

namespace abcube {

class SceneCache {
 public:
  // `scene` must outlive the cache; only its geometry, objects and materials are read.
  explicit SceneCache(const SceneData& scene) : scene_(&scene) {}

  std::shared_ptr<const MeshNeighbours> neighbours() const;
  std::shared_ptr<const std::vector<LensFit>> lenses() const;
  std::shared_ptr<const Bvh> bvh() const;

  // How many times each piece was built (0 or 1) and how long that took.
  struct Builds {
    int neighbours = 0, lenses = 0, bvh = 0;
    double neighbours_ms = 0, lenses_ms = 0, bvh_ms = 0;
  };
  Builds builds() const;

 private:
  const SceneData* scene_;
  mutable std::once_flag neighbours_once_, lenses_once_, bvh_once_;
  mutable std::shared_ptr<const MeshNeighbours> neighbours_;
  mutable std::shared_ptr<const std::vector<LensFit>> lenses_;
  mutable std::shared_ptr<const Bvh> bvh_;
  mutable Builds builds_;  // each piece's fields written once, inside its call_once,
  mutable std::atomic<bool> neighbours_done_{false}, lenses_done_{false}, bvh_done_{false};  // then set
};

}  // namespace abcube
