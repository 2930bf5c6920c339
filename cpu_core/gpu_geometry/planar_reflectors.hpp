// The flat mirrors of a scene: each a portal that the gpu method renders exactly, by
// virtual objects and the stencil test (course notes 4.1.2; Kilgard 1999, "Improving
// shadows and reflections via the stencil buffer"), where the cube-map methods approximate.
//
// A triangle belongs to a planar reflector when its material reflects (kr > 0) and neither
// refracts (kt = 0: refraction keeps the cube map) nor is coverage-transparent (opacity 1),
// and it is flat: its three shading normals are its geometric normal (or its opposite), so
// the mirror ray of the exact tracer (shading.hpp, about the shading normal) is the one of
// its plane. The flat reflective triangles of one object, one material and one plane make
// one reflector. Reflective triangles with smooth normals (a sphere) are curved: they keep
// the cube-map methods, and are counted. So are the flat facets of an object with more than
// MAX_PLANES_PER_OBJECT planes (a faceted metal part: thousands of mirrors a few pixels
// wide, each a view of its own) and, past MAX_REFLECTORS in the scene, the smallest ones by
// area: each reflector costs the stencil pass a view per level it is seen at.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene_data.hpp"

namespace abcube {

struct PlanarReflector {
  glm::dvec3 normal{0.0};  // unit, the first triangle's geometric normal
  double offset = 0;       // the plane: dot(normal, x) + offset = 0
  uint32_t object = 0, material = 0;
  std::vector<uint32_t> triangles;  // in the soup, ascending

  double side(const glm::dvec3& p) const { return glm::dot(normal, p) + offset; }
};

struct PlanarReflectors {
  std::vector<PlanarReflector> reflectors;  // in the order of their objects
  // Per triangle of the soup: 0, or the index of its reflector plus 1.
  std::vector<uint32_t> reflector_of_triangle;
  uint64_t curved_triangles = 0;  // reflective (kr > 0, kt = 0, opacity 1) but not flat, or left out (above)
};

// Flatness: every shading normal within this of +-(the geometric normal) (1 - cos); plane
// equality: normals as close, and offsets within PLANE_RELATIVE of the largest coordinate.
constexpr double FLAT_COSINE_TOLERANCE = 1e-6;
constexpr double PLANE_RELATIVE = 1e-6;
constexpr size_t MAX_PLANES_PER_OBJECT = 8;  // a box has 6
constexpr size_t MAX_REFLECTORS = 64;

PlanarReflectors find_planar_reflectors(const SceneData& scene);

}  // namespace abcube
