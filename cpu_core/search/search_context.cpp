// SearchContext: the geometry the searches need per cube map (planes, refinement bounds,
// zero-area triangles, where each face holds fragments, BLOCK BOUNDS), and the scene's
// mesh neighbours (docs/design/search.md, MESH REFINEMENT).
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>

#include "raster/raster.hpp"
#include "scene/tessellate.hpp"
#include "search/search.hpp"

namespace abcube {

namespace {

std::atomic<uint64_t> next_memo_id{1};

}  // namespace

SearchContext::SearchContext(const SceneData& scene, const CubeABuffer& cube,
                             std::shared_ptr<const MeshNeighbours> neighbours)
    : SearchContext(scene, cube, NeighboursSource([given = std::move(neighbours)] { return given; })) {}

SearchContext::SearchContext(const SceneData& scene, const CubeABuffer& cube, const NeighboursSource& neighbours)
    : scene_(&scene),
      cube_(&cube),
      media_(scene),
      positions_(scene.triangles->positions.data()),
      memo_id_(next_memo_id.fetch_add(1)) {
  const TriangleSoup& soup = *scene.triangles;
  const uint32_t count = static_cast<uint32_t>(soup.triangle_count());
  // The raster's own rule decides which triangles the map cannot hold (raster.hpp).
  for (uint32_t k = 0; k < count; ++k) {
    if (triangle_shape(cube.centre, soup, k) == SetupResult::edge_on) zero_area_.push_back(k);
  }
  // Where each face holds fragments, row by row (empty_ahead), BLOCK BOUNDS, and which
  // triangles have a fragment (THE SIDE STRUCTURE).
  std::vector<uint8_t> seen(count, 0);
  const int n = cube.n;
  blocks_per_row_ = (std::max(n, 0) + BOUNDS_BLOCK - 1) / BOUNDS_BLOCK;
  for (size_t f = 0; f < occupied_.size(); ++f) {
    RowBounds& rb = occupied_[f];
    const ABuffer& b = cube.faces[f];
    const bool known =
        b.width() == n && b.height() == n && b.offsets.size() == static_cast<size_t>(n) * static_cast<size_t>(n) + 1;
    // A face not laid out as n x n lists is taken as full: never skipped.
    rb.min_row.assign(static_cast<size_t>(std::max(n, 0)), known ? n : 0);
    rb.max_row.assign(static_cast<size_t>(std::max(n, 0)), known ? -1 : n - 1);
    for (int j = 0; known && j < n; ++j) {
      const uint32_t* row = b.offsets.data() + static_cast<size_t>(j) * static_cast<size_t>(n);
      for (int i = 0; i < n; ++i) {
        if (row[i + 1] == row[i]) continue;
        rb.min_row[static_cast<size_t>(j)] = std::min(rb.min_row[static_cast<size_t>(j)], i);
        rb.max_row[static_cast<size_t>(j)] = i;
      }
    }
    // A face not laid out as n x n lists gets blocks spanning every depth: never passed.
    const float inf = std::numeric_limits<float>::infinity();
    block_z_[f].assign(static_cast<size_t>(blocks_per_row_) * static_cast<size_t>(blocks_per_row_),
                       known ? glm::vec2(inf, -inf) : glm::vec2(-inf, inf));
    if (!known) std::fill(seen.begin(), seen.end(), uint8_t{1});  // unknown layout: no side structure
    for (int j = 0; known && j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        glm::vec2& z = block_z_[f][static_cast<size_t>(j / BOUNDS_BLOCK) * static_cast<size_t>(blocks_per_row_) +
                                   static_cast<size_t>(i / BOUNDS_BLOCK)];
        for (const Fragment& frag : b.list(i, j)) {
          z.x = std::min(z.x, frag.zmin);
          z.y = std::max(z.y, frag.zmax);
          if (frag.triangle() < count) seen[frag.triangle()] = 1;
        }
      }
    }
    rb.min_prefix = rb.min_row;
    rb.max_prefix = rb.max_row;
    for (size_t j = 1; j < rb.min_prefix.size(); ++j) {
      rb.min_prefix[j] = std::min(rb.min_prefix[j], rb.min_prefix[j - 1]);
      rb.max_prefix[j] = std::max(rb.max_prefix[j], rb.max_prefix[j - 1]);
    }
    rb.min_suffix = rb.min_row;
    rb.max_suffix = rb.max_row;
    for (size_t j = rb.min_suffix.size(); j-- > 1;) {
      rb.min_suffix[j - 1] = std::min(rb.min_suffix[j - 1], rb.min_suffix[j]);
      rb.max_suffix[j - 1] = std::max(rb.max_suffix[j - 1], rb.max_suffix[j]);
    }
  }
  build_pyramid();
  // The neighbours first: their build's hash table (a few bytes a triangle for a moment)
  // then comes before the side structure's tree, whose build holds one chunk at a time
  // (docs/design/bvh.md "Memory"), and the peak is the smaller.
  if (neighbours) neighbours_ = neighbours();
  if (!neighbours_) neighbours_ = std::make_shared<const MeshNeighbours>(build_mesh_neighbours(soup));
  build_side_structure(std::move(seen));
}

// THE Z PYRAMID (search.hpp): each level from the 2 x 2 nodes of the one below, halving
// (rounding up) until one node covers the face.
void SearchContext::build_pyramid() {
  level_width_.assign(1, static_cast<size_t>(blocks_per_row_));
  level_offset_.assign(1, 0);
  size_t total = 0;
  while (level_width_.back() > 1) {
    level_offset_.push_back(total);
    level_width_.push_back((level_width_.back() + 1) / 2);
    total += level_width_.back() * level_width_.back();
  }
  const float inf = std::numeric_limits<float>::infinity();
  for (size_t f = 0; f < pyramid_.size(); ++f) {
    pyramid_[f].assign(total, glm::vec2(inf, -inf));
    for (size_t k = 1; k < level_width_.size(); ++k) {
      const size_t below = level_width_[k - 1], width = level_width_[k];
      const glm::vec2* from = k == 1 ? block_z_[f].data() : pyramid_[f].data() + level_offset_[k - 1];
      glm::vec2* to = pyramid_[f].data() + level_offset_[k];
      for (size_t y = 0; y < below; ++y) {
        for (size_t x = 0; x < below; ++x) {
          glm::vec2& z = to[(y / 2) * width + x / 2];
          z.x = std::min(z.x, from[y * below + x].x);
          z.y = std::max(z.y, from[y * below + x].y);
        }
      }
    }
  }
}

size_t SearchContext::pyramid_bytes() const {
  size_t bytes = 0;
  for (const auto& p : pyramid_) bytes += p.size() * sizeof(glm::vec2);
  return bytes;
}

size_t SearchContext::block_bounds_bytes() const {
  size_t bytes = 0;
  for (const auto& b : block_z_) bytes += b.size() * sizeof(glm::vec2);
  return bytes;
}

// THE SIDE STRUCTURE (search.hpp): the zero-area triangles and those without a fragment,
// non-degenerate (a plane), in a BVH of their own.
void SearchContext::build_side_structure(std::vector<uint8_t> seen) {
  std::vector<uint32_t> side;
  for (uint32_t k = 0; k < seen.size(); ++k) {
    const bool zero_area = std::binary_search(zero_area_.begin(), zero_area_.end(), k);
    if ((zero_area || !seen[k]) && plane(k).normal != glm::dvec3(0.0)) side.push_back(k);
  }
  seen = std::vector<uint8_t>();  // freed before the tree is built
  if (side.empty()) return;
  side.shrink_to_fit();
  side_bvh_ = std::make_shared<const Bvh>(*scene_->triangles, std::move(side));
}

// Vertices are the same when their object and float position are (bit for bit, -0 = +0);
// an edge links the two triangles that have it, in either direction (tessellate.hpp).
MeshNeighbours build_mesh_neighbours(const TriangleSoup& soup) {
  MeshNeighbours neighbours{edge_partners(soup, 0, soup.triangle_count())};
  for (uint32_t& q : neighbours.across) q = q == NO_PARTNER ? SearchContext::NO_NEIGHBOUR : q / 3;
  return neighbours;
}

bool SearchContext::empty_ahead(int face, int i, int j, int step_i, int step_j) const {
  const RowBounds& rb = occupied_[static_cast<size_t>(face)];
  const size_t row = static_cast<size_t>(j);
  // The occupied columns over the rows the walk may still visit.
  const int lo = step_j > 0 ? rb.min_suffix[row] : (step_j < 0 ? rb.min_prefix[row] : rb.min_row[row]);
  const int hi = step_j > 0 ? rb.max_suffix[row] : (step_j < 0 ? rb.max_prefix[row] : rb.max_row[row]);
  if (step_i > 0) return hi < i;
  if (step_i < 0) return lo > i;
  return hi < i || lo > i;  // column i only
}

// The plane as plane() computes it, the same expressions on the same vertices.
SearchContext::EdgePlanes SearchContext::compute_edge_planes(uint32_t triangle) const {
  EdgePlanes e;
  const glm::dvec3 v[3] = {vertex(triangle, 0), vertex(triangle, 1), vertex(triangle, 2)};
  const glm::dvec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
  const double len = glm::length(n);
  if (!(len > 0.0 && std::isfinite(len))) return e;
  const glm::dvec3 unit = n / len;
  e.plane = {unit, glm::dot(unit, v[0])};
  for (size_t k = 0; k < 3; ++k) {
    const glm::dvec3 m = glm::cross(unit, v[(k + 1) % 3] - v[k]);
    const double ml = glm::length(m);
    if (ml > 0.0) e.edge_normal[k] = m / ml;
    e.edge_offset[k] = glm::dot(e.edge_normal[k], v[k]);
  }
  return e;
}

SearchContext::Sphere SearchContext::compute_bounding_sphere(uint32_t triangle) const {
  Sphere s;
  const glm::dvec3 v[3] = {vertex(triangle, 0), vertex(triangle, 1), vertex(triangle, 2)};
  const double len = glm::length(glm::cross(v[1] - v[0], v[2] - v[0]));
  if (!(len > 0.0 && std::isfinite(len))) return s;
  s.centroid = (v[0] + v[1] + v[2]) / 3.0;
  double farthest2 = 0.0;  // one square root: sqrt is monotone and correctly rounded
  for (const glm::dvec3& corner : v)
    farthest2 = std::max(farthest2, glm::dot(corner - s.centroid, corner - s.centroid));
  s.radius = std::sqrt(farthest2);
  return s;
}

}  // namespace abcube
