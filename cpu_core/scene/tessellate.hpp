// Scene primitives as triangles, the object transform, and closed-surface tests
// (docs/scene-format.md "objects"). Winding: the geometric normal is cross(b-a, c-a); on a
// closed object it points outward.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene_data.hpp"

namespace abcube {

// One object's triangles in its own space, before the transform: corners 3i..3i+2 are
// triangle i. `normals` is empty (flat shading) or holds one normal per corner, where a
// zero normal anywhere in a triangle means "flat" for that triangle. `material` is empty
// or holds one entry per triangle, -1 meaning the object's own material.
// Indexed (OBJ files, whose corners share vertices): when `indexed`, corner c is positions[position_index[c]] with
// normal normals[normal_index[c]] (a zero normal for NO_NORMAL), so a shared vertex is held once. Texture coordinates:
// `uvs` is empty (none) or, like normals, one per corner, or indexed by `uv_index` (NO_UV: that corner has none, (0,
// 0)). u runs right and v up the image, as in OBJ's vt; a loader whose format runs v down (glTF) stores 1 - v.
struct LocalMesh {
  std::vector<glm::dvec3> positions;
  std::vector<glm::dvec3> normals;
  std::vector<glm::dvec2> uvs;
  std::vector<int> material;
  static constexpr uint32_t NO_NORMAL = 0xffffffffu;
  static constexpr uint32_t NO_UV = 0xffffffffu;
  bool indexed = false;
  std::vector<uint32_t> position_index, normal_index, uv_index;
  size_t triangle_count() const { return (indexed ? position_index.size() : positions.size()) / 3; }
  const glm::dvec3& position(size_t corner) const { return positions[indexed ? position_index[corner] : corner]; }
  glm::dvec3 normal(size_t corner) const {
    if (!indexed) return normals[corner];
    return normal_index[corner] == NO_NORMAL ? glm::dvec3(0.0) : normals[normal_index[corner]];
  }
  glm::dvec2 uv(size_t corner) const {
    if (uvs.empty()) return glm::dvec2(0.0);
    if (!indexed) return uvs[corner];
    return uv_index[corner] == NO_UV ? glm::dvec2(0.0) : uvs[uv_index[corner]];
  }
};

// The primitives carry texture coordinates (docs/models-and-textures.md "Textures"): a
// triangle's corners (0, 0), (1, 0), (0, 1); a quad's corners in the order given
// (0, 0), (1, 0), (1, 1), (0, 1); each face of a box the same square, seen from outside; a
// sphere latitude-longitude.
LocalMesh tessellate_triangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

// How far the four quad vertices are from their best plane, relative to the quad's size
// (largest diagonal): 0 for a planar quad.
double quad_planarity_error(const std::array<glm::dvec3, 4>& v);

// Two triangles along a diagonal that keeps the quad's winding (either diagonal of a
// convex quad, the inner one of a concave quad). False for a self-intersecting quad.
bool tessellate_quad(const std::array<glm::dvec3, 4>& v, LocalMesh* out);

// Closed axis-aligned box, 12 triangles, flat normals, outward winding. lo < hi.
LocalMesh tessellate_box(const glm::dvec3& lo, const glm::dvec3& hi);

// Latitude-longitude sphere: `segments` around the equator, sphere_rings(segments)
// bands from pole (+y) to pole (-y); closed, outward winding, smooth normals.
int sphere_rings(int segments);
size_t sphere_triangle_count(int segments);
LocalMesh tessellate_sphere(const glm::dvec3& center, double radius, int segments);

// Splits a simple polygon (corners in order) into triangles of the same winding by ear
// clipping in the plane of its Newell normal (Eberly 2002, "Triangulation by Ear
// Clipping"). Corner index triples; what no ear can be cut from is fanned.
std::vector<std::array<int, 3>> triangulate_polygon(const std::vector<glm::dvec3>& corners);

// Object to world: scale, then rotate about x, then y, then z (degrees), then translate.
struct Transform {
  glm::dvec3 translate{0.0};
  glm::dvec3 rotate_deg{0.0};
  glm::dvec3 scale{1.0};
};

struct AffineMap {
  glm::dmat3 linear{1.0};
  glm::dvec3 offset{0.0};
  glm::dmat3 normal_matrix{1.0};  // inverse transpose of `linear`
  bool mirrors = false;           // det(linear) < 0: winding must flip to keep normals
  glm::dvec3 point(const glm::dvec3& p) const { return linear * p + offset; }
};
AffineMap make_affine_map(const Transform& t);

// True when the triangle has no usable area: |cross(b-a, c-a)| <= 1e-12 * (longest
// edge)^2, or non-finite corners.
bool is_zero_area(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

// Appends `local`, moved to world space by `m`, to `soup` as object `object_id`; triangles
// without a material entry (or with -1) get `material`. Triangles that are zero-area or
// non-finite once stored as floats are skipped; returns how many were. On up to `threads`
// threads (0: every core); the same soup for any number.
size_t append_triangles(const LocalMesh& local, const AffineMap& m, uint32_t object_id, uint32_t material,
                        TriangleSoup* soup, int threads = 0);

// The half-edges of triangles [first, first + count) of the soup: half-edge 3 i + k runs
// from corner k to corner k + 1 of triangle first + i. A vertex is an object and a float
// position (bit for bit, -0 = +0). Returns each half-edge's partner, the other half-edge
// with the same two vertices (in either direction) when exactly two have them, else
// NO_PARTNER (a border, an edge of three or more, or one whose two ends are one vertex).
// Hash tables, no sort: 4 bytes a half-edge, and at most about 20 more while it works.
constexpr uint32_t NO_PARTNER = 0xffffffffu;
std::vector<uint32_t> edge_partners(const TriangleSoup& soup, size_t first, size_t count);

// Whether triangles [first, first + count) of the soup form a closed, consistently
// oriented surface: every edge (by exact vertex position) is shared by exactly two
// triangles that run along it in opposite directions.
bool is_closed_surface(const TriangleSoup& soup, size_t first, size_t count);

// Signed volume enclosed by the triangles (divergence theorem, sum of tetrahedra
// (o, a, b, c)); positive when a closed surface's normals point outward.
double signed_volume(const TriangleSoup& soup, size_t first, size_t count);

// Reverses the winding of the triangles (swaps corners b and c with their normals) and
// turns every normal that then points against the new geometric normal (all flat ones).
void flip_winding(TriangleSoup* soup, size_t first, size_t count);

}  // namespace abcube
