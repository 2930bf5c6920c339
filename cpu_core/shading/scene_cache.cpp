#include "shading/scene_cache.hpp"

#include "base/timer.hpp"

namespace abcube {

std::shared_ptr<const MeshNeighbours> SceneCache::neighbours() const {
  std::call_once(neighbours_once_, [this] {
    const Clock::time_point t0 = Clock::now();
    neighbours_ = std::make_shared<const MeshNeighbours>(build_mesh_neighbours(*scene_->triangles));
    builds_.neighbours_ms = ms_since(t0);
    builds_.neighbours = 1;
    neighbours_done_.store(true, std::memory_order_release);
  });
  return neighbours_;
}

std::shared_ptr<const std::vector<LensFit>> SceneCache::lenses() const {
  std::call_once(lenses_once_, [this] {
    const Clock::time_point t0 = Clock::now();
    lenses_ = std::make_shared<const std::vector<LensFit>>(fit_lenses(*scene_));
    builds_.lenses_ms = ms_since(t0);
    builds_.lenses = 1;
    lenses_done_.store(true, std::memory_order_release);
  });
  return lenses_;
}

std::shared_ptr<const Bvh> SceneCache::bvh() const {
  std::call_once(bvh_once_, [this] {
    const Clock::time_point t0 = Clock::now();
    bvh_ = std::make_shared<const Bvh>(*scene_->triangles);
    builds_.bvh_ms = ms_since(t0);
    builds_.bvh = 1;
    bvh_done_.store(true, std::memory_order_release);
  });
  return bvh_;
}

SceneCache::Builds SceneCache::builds() const {
  // A piece's figures are read only once its flag says its call_once has finished.
  Builds b;
  if (neighbours_done_.load(std::memory_order_acquire))
    b.neighbours = builds_.neighbours, b.neighbours_ms = builds_.neighbours_ms;
  if (lenses_done_.load(std::memory_order_acquire)) b.lenses = builds_.lenses, b.lenses_ms = builds_.lenses_ms;
  if (bvh_done_.load(std::memory_order_acquire)) b.bvh = builds_.bvh, b.bvh_ms = builds_.bvh_ms;
  return b;
}

}  // namespace abcube
