#include "scene/shadow_volume.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "shading/shading.hpp"

namespace abcube {

namespace {

// An edge of an oriented near cap, keyed by its endpoints' float bits (the soup's vertices
// of neighbours are the same floats), lo < hi; `forward`: traversed lo -> hi.
struct DirectedEdge {
  std::array<uint32_t, 6> key;
  glm::vec3 lo, hi;
  uint32_t object;
  bool forward;
};

std::array<uint32_t, 3> bits(const glm::vec3& p) {
  std::array<uint32_t, 3> b;
  std::memcpy(b.data(), &p.x, sizeof(float) * 3);
  return b;
}

glm::vec4 at_infinity(const glm::vec3& p, const glm::dvec3& light) {
  const glm::dvec3 d = glm::dvec3(p) - light;
  return glm::vec4(glm::vec3(d), 0.f);
}

}  // namespace

ShadowVolume build_shadow_volume(const SceneData& scene, const glm::dvec3& light, Blockers kind) {
  const TriangleSoup& soup = *scene.triangles;
  ShadowVolume out;
  std::vector<DirectedEdge> edges;
  auto push = [&out](const glm::vec4& p, uint32_t object, bool reversed) {
    out.vertices.push_back({p, object, reversed ? 1u : 0u});
  };
  for (uint32_t t = 0; t < soup.triangle_count(); ++t) {
    const glm::dvec3 through = blocker_transmittance(scene.materials[soup.material_id[t]]);
    const bool opaque = through == glm::dvec3(0.0), clear = through == glm::dvec3(1.0);
    if (kind == Blockers::opaque ? !opaque : (opaque || clear)) continue;
    if (plane_holds_light(soup, t, light)) continue;             // a light on this surface: no blocker
    const size_t v = 3 * static_cast<size_t>(t);
    const glm::vec3 p[3] = {soup.positions[v], soup.positions[v + 1], soup.positions[v + 2]};
    const glm::dvec3 a(p[0]), b(p[1]), c(p[2]);
    const double facing = glm::dot(glm::cross(b - a, c - a), light - a);
    if (!(facing != 0.0) || !std::isfinite(facing)) continue;  // degenerate, or edge-on to the light
    const bool reversed = facing < 0.0;  // oriented cap: (a, c, b)
    const uint32_t object = soup.object_id[t];
    // A closed object's triangles facing away from the light add nothing: a segment from a
    // point to the light that meets the object enters it, seen from the light, through a
    // triangle facing the light, whose prism holds the point (its winding faces out:
    // scene_load.cpp). Their prisms only doubled the count inside those, and the fill.
    if (reversed && scene.objects[object].closed) continue;
    ++out.blockers;
    // Near cap, the triangle's own vertices in their own order; far cap, reversed.
    for (int k = 0; k < 3; ++k) push(glm::vec4(p[k], 1.f), object, reversed);
    const int order[3] = {0, reversed ? 1 : 2, reversed ? 2 : 1};  // the oriented cap (a, c, b) reversed
    for (int k = 0; k < 3; ++k) push(at_infinity(p[order[k]], light), object, false);
    // The oriented cap's edges u -> v.
    const int cap[3] = {0, reversed ? 2 : 1, reversed ? 1 : 2};
    for (int k = 0; k < 3; ++k) {
      const glm::vec3& u = p[cap[k]];
      const glm::vec3& w = p[cap[(k + 1) % 3]];
      const std::array<uint32_t, 3> bu = bits(u), bw = bits(w);
      const bool forward = bu < bw;
      DirectedEdge e;
      e.lo = forward ? u : w;
      e.hi = forward ? w : u;
      const std::array<uint32_t, 3>& l = forward ? bu : bw;
      const std::array<uint32_t, 3>& h = forward ? bw : bu;
      e.key = {l[0], l[1], l[2], h[0], h[1], h[2]};
      e.object = object;
      e.forward = forward;
      edges.push_back(e);
    }
  }
  // Sides: per edge, the directions that do not cancel in pairs.
  std::sort(edges.begin(), edges.end(), [](const DirectedEdge& x, const DirectedEdge& y) { return x.key < y.key; });
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    long net = 0;
    for (; j < edges.size() && edges[j].key == edges[i].key; ++j) net += edges[j].forward ? 1 : -1;
    const long count = net < 0 ? -net : net;
    out.sides_cancelled += (j - i) - static_cast<size_t>(count);
    const glm::vec3 u = net > 0 ? edges[i].lo : edges[i].hi;
    const glm::vec3 w = net > 0 ? edges[i].hi : edges[i].lo;
    for (long n = 0; n < count; ++n) {
      // The side of edge u -> w, outward: (u, u_inf, w_inf) and (u, w_inf, w).
      const glm::vec4 u1(u, 1.f), w1(w, 1.f), ui = at_infinity(u, light), wi = at_infinity(w, light);
      for (const glm::vec4& q : {u1, ui, wi, u1, wi, w1}) push(q, edges[i].object, false);
      ++out.sides;
    }
    i = j;
  }
  return out;
}

}  // namespace abcube
