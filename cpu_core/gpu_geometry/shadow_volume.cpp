#include "gpu_geometry/shadow_volume.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "base/constants.hpp"
#include "material/shading.hpp"

namespace abcube {

namespace {

std::array<uint32_t, 3> bits(const glm::vec3& p) {
  std::array<uint32_t, 3> b;
  std::memcpy(b.data(), &p.x, sizeof(float) * 3);
  return b;
}

// An edge of an oriented near cap, keyed by its endpoints' float bits (the soup's vertices
// of neighbours are the same floats), lo < hi; `forward`: traversed lo -> hi. 32 bytes, the
// key read from lo and hi when sorting (PAIRING_EDGE_BYTES).
struct DirectedEdge {
  glm::vec3 lo, hi;
  uint32_t object;
  bool forward;
  std::array<uint32_t, 6> key() const {
    const std::array<uint32_t, 3> l = bits(lo), h = bits(hi);
    return {l[0], l[1], l[2], h[0], h[1], h[2]};
  }
  uint64_t hash() const {  // of the key, mixed (splitmix64's finaliser per word)
    uint64_t h = 0x9e3779b97f4a7c15ull;
    for (const uint32_t x : key()) {
      h ^= x;
      h *= 0xff51afd7ed558ccdull;
      h ^= h >> 33;
    }
    return h;
  }
};

glm::vec4 at_infinity(const glm::vec3& p, const glm::dvec3& light) {
  const glm::dvec3 d = glm::dvec3(p) - light;
  return glm::vec4(glm::vec3(d), 0.f);
}

// The far cap of blocker t (code CAP or CAP_REVERSED): its corners pushed to infinity, in
// the order that orients it outward, away from the light (the oriented cap (a, c, b)
// reversed).
std::array<glm::vec4, 3> far_cap(const TriangleSoup& soup, uint32_t t, uint8_t code, const glm::dvec3& light) {
  const glm::vec3* p = &soup.positions[3 * static_cast<size_t>(t)];
  const bool reversed = code == CAP_REVERSED;
  return {at_infinity(p[0], light), at_infinity(p[reversed ? 1 : 2], light), at_infinity(p[reversed ? 2 : 1], light)};
}

static_assert(sizeof(DirectedEdge) == PAIRING_EDGE_BYTES, "the memory estimate counts the pairing's edges");

}  // namespace

std::vector<uint8_t> lights_outside_closed(const SceneData& scene, const glm::dvec3& light) {
  const TriangleSoup& soup = *scene.triangles;
  std::vector<double> solid_angle(scene.objects.size(), 0.0);
  std::vector<uint8_t> on_plane(scene.objects.size(), 0);
  for (uint32_t t = 0; t < soup.triangle_count(); ++t) {
    const uint32_t object = soup.object_id[t];
    if (!scene.objects[object].closed || on_plane[object]) continue;
    if (plane_holds_light(soup, t, light)) {
      on_plane[object] = 1;
      continue;
    }
    const size_t v = 3 * static_cast<size_t>(t);
    const glm::dvec3 a = glm::dvec3(soup.positions[v]) - light, b = glm::dvec3(soup.positions[v + 1]) - light,
                     c = glm::dvec3(soup.positions[v + 2]) - light;
    const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
    const double num = glm::dot(a, glm::cross(b, c));
    const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
    solid_angle[object] += 2.0 * std::atan2(num, den);
  }
  std::vector<uint8_t> outside(scene.objects.size(), 0);
  constexpr double FOUR_PI = 4.0 * PI;
  for (size_t o = 0; o < outside.size(); ++o) {
    // Off the surface the winding number is an integer up to rounding: below 1/2 is 0.
    outside[o] = scene.objects[o].closed && !on_plane[o] && std::fabs(solid_angle[o] / FOUR_PI) < 0.5;
  }
  return outside;
}

namespace {

// The caps: each triangle that casts for `kind` gets its cap, oriented (reversed: (a, c, b))
// to face the light.
void mark_caps(const SceneData& scene, const glm::dvec3& light, Blockers kind, ShadowVolume* out) {
  const TriangleSoup& soup = *scene.triangles;
  const std::vector<uint8_t> outside = lights_outside_closed(scene, light);
  // Whether triangle t casts, and how its cap is oriented.
  auto casts = [&](uint32_t t, bool* reversed) {
    const glm::dvec3 through = blocker_transmittance(scene.materials[soup.material_id[t]]);
    const bool opaque = through == glm::dvec3(0.0), clear = through == glm::dvec3(1.0);
    if (kind == Blockers::opaque ? !opaque : (opaque || clear)) return false;
    if (plane_holds_light(soup, t, light)) return false;  // a light on this surface: no blocker
    const size_t v = 3 * static_cast<size_t>(t);
    const glm::dvec3 a(soup.positions[v]), b(soup.positions[v + 1]), c(soup.positions[v + 2]);
    const double facing = glm::dot(glm::cross(b - a, c - a), light - a);
    if (!(facing != 0.0) || !std::isfinite(facing)) return false;  // degenerate, or edge-on to the light
    *reversed = facing < 0.0;
    // A closed object's triangles facing away from a light strictly outside it add nothing:
    // a segment from a point to the light that meets the object enters it, seen from the
    // light, through a triangle facing the light (the winding faces out: tessellate.hpp),
    // whose prism holds the point; theirs would only double the count and the fill. With the
    // light on the object's surface (a face there casts nothing) or inside it, that segment
    // may cross no light-facing triangle, so every triangle casts there, and only objects
    // strictly outside which the light lies drop theirs (tests/cli/flat_mirrors.sh,
    // light_on_mirror_1_4; ShadowVolume.AClosedBoxCastsFromEveryFace).
    if (*reversed && outside[soup.object_id[t]]) {
      ++out->facing_away_left_out;
      return false;
    }
    return true;
  };
  out->caps.assign(soup.triangle_count(), NO_CAP);
  for (uint32_t t = 0; t < soup.triangle_count(); ++t) {
    bool reversed = false;
    if (!casts(t, &reversed)) continue;
    out->caps[t] = reversed ? CAP_REVERSED : CAP;
    ++out->blockers;
  }
}

// Calls f(i, edge) for the i-th edge u -> w of the oriented caps, in a fixed order.
template <class F>
void for_each_cap_edge(const TriangleSoup& soup, const ShadowVolume& volume, const F& f) {
  uint64_t i = 0;
  for (uint32_t t = 0; t < soup.triangle_count(); ++t) {
    if (volume.caps[t] == NO_CAP) continue;
    const bool reversed = volume.caps[t] == CAP_REVERSED;
    const glm::vec3* p = &soup.positions[3 * static_cast<size_t>(t)];
    const int cap[3] = {0, reversed ? 2 : 1, reversed ? 1 : 2};
    for (int k = 0; k < 3; ++k) {
      const glm::vec3& u = p[cap[k]];
      const glm::vec3& w = p[cap[(k + 1) % 3]];
      const bool forward = bits(u) < bits(w);
      f(i++, DirectedEdge{forward ? u : w, forward ? w : u, soup.object_id[t], forward});
    }
  }
}

// The sides of a set of cap edges holding every copy of each of its edges: sorted, per edge
// the directions that do not cancel in pairs, each a side drawn outward.
void add_sides(std::vector<DirectedEdge>* edges, const glm::dvec3& light, ShadowVolume* out) {
  std::sort(edges->begin(), edges->end(),
            [](const DirectedEdge& x, const DirectedEdge& y) { return x.key() < y.key(); });
  const std::vector<DirectedEdge>& sorted = *edges;
  for (size_t i = 0; i < sorted.size();) {
    size_t j = i;
    long net = 0;
    const std::array<uint32_t, 6> key = sorted[i].key();
    for (; j < sorted.size() && sorted[j].key() == key; ++j) net += sorted[j].forward ? 1 : -1;
    const long count = net < 0 ? -net : net;
    out->sides_cancelled += (j - i) - static_cast<size_t>(count);
    out->sides += static_cast<uint64_t>(count);
    const DirectedEdge& e = sorted[i];
    const glm::vec3 u = net > 0 ? e.lo : e.hi;
    const glm::vec3 w = net > 0 ? e.hi : e.lo;
    for (long n = 0; n < count; ++n) {
      // The side of edge u -> w, outward: (u, u_inf, w_inf) and (u, w_inf, w).
      const glm::vec4 u1(u, 1.f), w1(w, 1.f), ui = at_infinity(u, light), wi = at_infinity(w, light);
      for (const glm::vec4& q : {u1, ui, wi, u1, wi, w1}) out->side_vertices.push_back({q, e.object, 0u});
    }
    i = j;
  }
}

}  // namespace

ShadowVolume build_shadow_volume(const SceneData& scene, const glm::dvec3& light, Blockers kind) {
  const TriangleSoup& soup = *scene.triangles;
  ShadowVolume out;
  out.light = light;
  mark_caps(scene, light, kind, &out);
  // The oriented caps' edges u -> w, sorted: per edge, the directions that do not cancel in
  // pairs are its sides. In buckets by a hash of the edge's endpoints, a bucket sorted at a
  // time, so that about PAIRING_BUCKET_EDGES edges are held at once whatever the scene's
  // size (all of them at once would set the gpu method's peak memory).
  const uint64_t edge_count = 3 * out.blockers;
  const uint32_t buckets = static_cast<uint32_t>(
      std::clamp<uint64_t>((edge_count + PAIRING_BUCKET_EDGES - 1) / PAIRING_BUCKET_EDGES, 1, 255));
  std::vector<uint8_t> bucket_of;  // per edge, when there are buckets
  std::vector<uint64_t> bucket_size(buckets, 0);
  if (buckets > 1) {
    bucket_of.resize(edge_count);
    for_each_cap_edge(soup, out, [&](uint64_t i, const DirectedEdge& e) {
      bucket_of[i] = static_cast<uint8_t>(e.hash() % buckets);
      ++bucket_size[bucket_of[i]];
    });
  } else {
    bucket_size[0] = edge_count;
  }
  std::vector<DirectedEdge> edges;
  edges.reserve(*std::max_element(bucket_size.begin(), bucket_size.end()));
  for (uint32_t bucket = 0; bucket < buckets; ++bucket) {
    edges.clear();
    for_each_cap_edge(soup, out, [&](uint64_t i, const DirectedEdge& e) {
      if (buckets == 1 || bucket_of[i] == bucket) edges.push_back(e);
    });
    add_sides(&edges, light, &out);
  }
  return out;
}

std::vector<ShadowVolumeVertex> volume_triangles(const ShadowVolume& volume, const TriangleSoup& soup) {
  std::vector<ShadowVolumeVertex> out;
  out.reserve(6 * volume.blockers + volume.side_vertices.size());
  for (uint32_t t = 0; t < soup.triangle_count(); ++t) {
    if (volume.caps[t] == NO_CAP) continue;
    const glm::vec3* p = &soup.positions[3 * static_cast<size_t>(t)];
    const uint32_t reversed = volume.caps[t] == CAP_REVERSED ? 1u : 0u;
    for (int k = 0; k < 3; ++k) out.push_back({glm::vec4(p[k], 1.f), soup.object_id[t], reversed});
    const std::array<glm::vec4, 3> far = far_cap(soup, t, volume.caps[t], volume.light);
    for (const glm::vec4& q : far) out.push_back({q, soup.object_id[t], 0u});
  }
  out.insert(out.end(), volume.side_vertices.begin(), volume.side_vertices.end());
  return out;
}

namespace {

// A corner of a polygon being clipped: homogeneous, relative to the eye (w = 0: a direction).
using Corner = glm::dvec4;

bool before(const Corner& a, const Corner& b) {
  for (int k = 0; k < 4; ++k) {
    if (a[k] != b[k]) return a[k] < b[k];
  }
  return false;
}

// The point of segment a-b on the plane (values da, db of opposite signs), computed from the
// segment's endpoints in one order whichever way it is traversed.
Corner cut(const Corner& a, double da, const Corner& b, double db) {
  if (before(b, a)) return cut(b, db, a, da);
  const double t = da / (da - db);
  return a + t * (b - a);
}

// Sutherland-Hodgman against one plane (kept: dot(plane, corner) >= 0), `in` to `out`.
void clip_polygon(const std::vector<Corner>& in, const glm::dvec4& plane, std::vector<Corner>* out) {
  out->clear();
  const size_t n = in.size();
  for (size_t i = 0; i < n; ++i) {
    const Corner& a = in[i];
    const Corner& b = in[(i + 1) % n];
    const double da = glm::dot(plane, a), db = glm::dot(plane, b);
    if (da >= 0.0) out->push_back(a);
    if ((da >= 0.0) != (db >= 0.0)) out->push_back(cut(a, da, b, db));
  }
}

}  // namespace

size_t clip_faces_at_infinity(const ShadowVolume& volume, const TriangleSoup& soup,
                              const glm::dmat4& clip_from_relative, const glm::dvec3& eye, double tie_step,
                              const glm::dvec4* plane, std::vector<ShadowVolumeVertex>* out, size_t first,
                              size_t count) {
  const glm::dmat4 t = glm::transpose(clip_from_relative);
  size_t written = 0;
  std::vector<Corner> a, b;
  std::vector<glm::vec4> window;
  const auto clip_face = [&](const std::array<glm::vec4, 3>& corners, uint32_t object, uint32_t reversed) {
    const double scale = 1.0 + tie_step * (double(object) + 1.0);
    // The planes, as functionals of the relative corner: w - x, w + x, w - y, w + y, w - s z.
    const glm::dvec4 planes[6] = {t * glm::dvec4(-1, 0, 0, 1),     t * glm::dvec4(1, 0, 0, 1),
                                  t * glm::dvec4(0, -1, 0, 1),     t * glm::dvec4(0, 1, 0, 1),
                                  t * glm::dvec4(0, 0, -scale, 1), plane ? *plane : glm::dvec4(0, 0, 0, 1)};
    const int plane_count = plane ? 6 : 5;
    a.clear();
    for (const glm::vec4& p : corners) {
      a.push_back(p.w == 0.f ? Corner(glm::dvec3(p), 0.0) : Corner(glm::dvec3(p) - eye, 1.0));
    }
    for (int q = 0; q < plane_count; ++q) {  // every corner beyond one plane: nothing of it is seen
      if (glm::dot(planes[q], a[0]) < 0.0 && glm::dot(planes[q], a[1]) < 0.0 && glm::dot(planes[q], a[2]) < 0.0) return;
    }
    for (int q = 0; q < plane_count && a.size() >= 3; ++q) {
      clip_polygon(a, planes[q], &b);
      a.swap(b);
    }
    if (a.size() < 3) return;
    // Window-space points: w > 0 on every corner kept (w >= |x|, and w = x = y = 0 only at
    // a degenerate corner, skipped).
    window.clear();
    for (const Corner& c : a) {
      const glm::dvec4 h = clip_from_relative * c;
      if (!(h.w > 0.0)) return;
      window.emplace_back(float(h.x / h.w), float(h.y / h.w), float(scale * h.z / h.w), 1.f);
    }
    for (size_t k = 1; k + 1 < window.size(); ++k) {
      for (const glm::vec4& v : {window[0], window[k], window[k + 1]}) out->push_back({v, object, reversed});
      ++written;
    }
  };
  const size_t triangles = volume.caps.size();
  const size_t end = first + std::min(count, faces_at_infinity(volume) - std::min(first, faces_at_infinity(volume)));
  for (size_t f = first; f < std::min(end, triangles); ++f) {
    const uint32_t tri = static_cast<uint32_t>(f);
    if (volume.caps[tri] != NO_CAP)
      clip_face(far_cap(soup, tri, volume.caps[tri], volume.light), soup.object_id[tri], 0u);
  }
  const std::vector<ShadowVolumeVertex>& sides = volume.side_vertices;
  for (size_t f = std::max(first, triangles); f < end; ++f) {
    const size_t i = 3 * (f - triangles);
    clip_face({sides[i].position, sides[i + 1].position, sides[i + 2].position}, sides[i].object, sides[i].reversed);
  }
  return written;
}

}  // namespace abcube
