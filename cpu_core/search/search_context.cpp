// SearchContext: the geometry the searches need per cube map (planes, refinement bounds,
// zero-area triangles, where each face holds fragments, BLOCK BOUNDS), and the scene's
// mesh neighbours (search.hpp MESH REFINEMENT).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <tuple>

#include "raster/raster.hpp"
#include "search/search.hpp"

namespace abcube {

// scene_load.cpp's memory estimate (TRIANGLE_BYTES) counts these sizes per triangle.
static_assert(sizeof(SearchContext::Plane) <= 32 && sizeof(SearchContext::TriangleBounds) <= 128,
              "update TRIANGLE_BYTES in scene_load.cpp");

SearchContext::SearchContext(const SceneData& scene, const CubeABuffer& cube,
                             std::shared_ptr<const MeshNeighbours> neighbours)
    : scene_(&scene), cube_(&cube), media_(scene), neighbours_(std::move(neighbours)) {
  const TriangleSoup& soup = *scene.triangles;
  const uint32_t count = static_cast<uint32_t>(soup.triangle_count());
  planes_.resize(count);
  bounds_.resize(count);
  // The raster's own rule decides which triangles the map cannot hold (raster.hpp).
  const RasterView view = cube_face_view(0, cube.centre, std::max(cube.n, 1), cube.near_distance);
  TriangleSetup setup;
  for (uint32_t k = 0; k < count; ++k) {
    const glm::dvec3 a = vertex(k, 0);
    const glm::dvec3 n = glm::cross(vertex(k, 1) - a, vertex(k, 2) - a);
    const double len = glm::length(n);
    if (len > 0.0 && std::isfinite(len)) {
      planes_[k] = {n / len, glm::dot(n / len, a)};
      TriangleBounds& b = bounds_[k];
      const glm::dvec3 v[3] = {a, vertex(k, 1), vertex(k, 2)};
      b.centroid = (v[0] + v[1] + v[2]) / 3.0;
      for (size_t e = 0; e < 3; ++e) {
        const glm::dvec3 m = glm::cross(n / len, v[(e + 1) % 3] - v[e]);
        const double ml = glm::length(m);
        if (ml > 0.0) b.edge_normal[e] = m / ml;
        b.edge_offset[e] = glm::dot(b.edge_normal[e], v[e]);
        b.radius = std::max(b.radius, glm::length(v[e] - b.centroid));
      }
    }
    if (setup_triangle(view, soup, k, &setup) == SetupResult::edge_on) zero_area_.push_back(k);
  }
  if (!neighbours_) neighbours_ = std::make_shared<const MeshNeighbours>(build_mesh_neighbours(soup));
  // Where each face holds fragments, row by row (empty_ahead), BLOCK BOUNDS, and which
  // triangles have a fragment (THE SIDE STRUCTURE).
  std::vector<uint8_t> seen(count, 0);
  const int n = cube.n;
  blocks_per_row_ = (std::max(n, 0) + BOUNDS_BLOCK - 1) / BOUNDS_BLOCK;
  for (size_t f = 0; f < occupied_.size(); ++f) {
    RowBounds& rb = occupied_[f];
    const ABuffer& b = cube.faces[f];
    const bool known = b.width() == n && b.height() == n &&
                       b.offsets.size() == static_cast<size_t>(n) * static_cast<size_t>(n) + 1;
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
  build_side_structure(seen);
}

// THE SIDE STRUCTURE (search.hpp): the zero-area triangles and those without a fragment,
// non-degenerate (a plane), in a BVH of their own.
void SearchContext::build_side_structure(const std::vector<uint8_t>& seen) {
  for (uint32_t k = 0; k < seen.size(); ++k) {
    const bool zero_area = std::binary_search(zero_area_.begin(), zero_area_.end(), k);
    if ((zero_area || !seen[k]) && planes_[k].normal != glm::dvec3(0.0)) side_.push_back(k);
  }
  if (side_.empty()) return;
  const TriangleSoup& soup = *scene_->triangles;
  TriangleSoup sub;
  for (const uint32_t k : side_) {
    for (size_t v = 0; v < 3; ++v) sub.positions.push_back(soup.positions[3 * static_cast<size_t>(k) + v]);
    sub.object_id.push_back(soup.object_id[k]);
    sub.material_id.push_back(soup.material_id[k]);
  }
  side_bvh_ = std::make_shared<const Bvh>(sub);
}

// Vertices are the same when their object and float position are (bit for bit, -0 = +0);
// an edge links the two triangles that have it, in either direction.
MeshNeighbours build_mesh_neighbours(const TriangleSoup& soup) {
  constexpr uint32_t NO_NEIGHBOUR = SearchContext::NO_NEIGHBOUR;
  const size_t count = soup.triangle_count();
  MeshNeighbours neighbours(count, {NO_NEIGHBOUR, NO_NEIGHBOUR, NO_NEIGHBOUR});
  struct Corner {
    uint32_t object;
    std::array<uint32_t, 3> bits;
    uint32_t index;  // 3 * triangle + k
  };
  std::vector<Corner> corners(3 * count);
  for (size_t c = 0; c < corners.size(); ++c) {
    const glm::vec3 v = soup.positions[c] + glm::vec3(0.0f);  // -0 -> +0
    Corner& k = corners[c];
    k.object = soup.object_id[c / 3];
    std::memcpy(k.bits.data(), &v[0], sizeof(float));
    std::memcpy(k.bits.data() + 1, &v[1], sizeof(float));
    std::memcpy(k.bits.data() + 2, &v[2], sizeof(float));
    k.index = static_cast<uint32_t>(c);
  }
  std::sort(corners.begin(), corners.end(), [](const Corner& a, const Corner& b) {
    return std::tie(a.object, a.bits, a.index) < std::tie(b.object, b.bits, b.index);
  });
  std::vector<uint32_t> vertex_id(corners.size());
  uint32_t id = 0;
  for (size_t c = 0; c < corners.size(); ++c) {
    if (c > 0 && (corners[c].object != corners[c - 1].object || corners[c].bits != corners[c - 1].bits)) ++id;
    vertex_id[corners[c].index] = id;
  }
  // (smaller vertex id, larger vertex id, 3 * triangle + edge), sorted: equal edges adjacent.
  std::vector<std::pair<uint64_t, uint32_t>> edges;
  edges.reserve(3 * count);
  for (size_t t = 0; t < count; ++t) {
    for (size_t k = 0; k < 3; ++k) {
      const uint64_t a = vertex_id[3 * t + k], b = vertex_id[3 * t + (k + 1) % 3];
      if (a == b) continue;
      edges.push_back({std::min(a, b) << 32 | std::max(a, b), static_cast<uint32_t>(3 * t + k)});
    }
  }
  std::sort(edges.begin(), edges.end());
  for (size_t e = 0; e < edges.size();) {
    size_t end = e + 1;
    while (end < edges.size() && edges[end].first == edges[e].first) ++end;
    if (end - e == 2) {  // manifold edge; a border (1) or a non-manifold edge (> 2) links nothing
      const uint32_t x = edges[e].second, y = edges[e + 1].second;
      neighbours[x / 3][x % 3] = y / 3;
      neighbours[y / 3][y % 3] = x / 3;
    }
    e = end;
  }
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

glm::dvec3 SearchContext::vertex(uint32_t triangle, int k) const {
  return glm::dvec3(scene_->triangles->positions[3 * static_cast<size_t>(triangle) + static_cast<size_t>(k)]) -
         cube_->centre;
}

}  // namespace abcube
