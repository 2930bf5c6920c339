#include "scene/tessellate.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "base/constants.hpp"
#include "base/error.hpp"
#include "base/parallel.hpp"

namespace abcube {

namespace {

// A triangle is zero-area when twice its area is below this share of its squared
// longest edge (a relative test, so it does not depend on the scene's units).
constexpr double ZERO_AREA_RELATIVE = 1e-12;

void push_triangle(LocalMesh* m, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  m->positions.push_back(a);
  m->positions.push_back(b);
  m->positions.push_back(c);
}

void push_uvs(LocalMesh* m, const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  m->uvs.push_back(a);
  m->uvs.push_back(b);
  m->uvs.push_back(c);
}

// A quad's corners 0..3 span the texture's square counter-clockwise from (0, 0).
constexpr double QUAD_UV[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
glm::dvec2 quad_uv(int corner) { return {QUAD_UV[corner][0], QUAD_UV[corner][1]}; }

// Rounds to float, out of line: inlined into append_triangles, GCC 12 -O3 (SLP vectorizer)
// can keep the double x and y where they are rounded, converted back, and the soup's
// normals then differ from the positions' by an ulp (tests/golden would catch it).
[[gnu::noinline]] glm::vec3 to_float(const glm::dvec3& v) { return glm::vec3(v); }

bool finite3(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Newell's method: twice the vector area of a polygon (Sutherland et al. 1974; Tampieri,
// "Newell's Method for Computing the Plane Equation of a Polygon", Graphics Gems III).
glm::dvec3 newell_normal(const glm::dvec3* v, size_t n) {
  glm::dvec3 c(0.0);
  for (size_t i = 0; i < n; ++i) c += v[i];
  c /= static_cast<double>(n);
  glm::dvec3 sum(0.0);
  for (size_t i = 0; i < n; ++i) sum += glm::cross(v[i] - c, v[(i + 1) % n] - c);
  return sum;
}

// cos and sin of an angle in degrees, exact at multiples of 90 so that quarter turns
// keep axis-aligned geometry axis-aligned.
void cos_sin_deg(double deg, double* c, double* s) {
  const double quarters = deg / 90.0;
  if (quarters == std::floor(quarters) && std::fabs(quarters) < 1e15) {
    static const double COS[4] = {1, 0, -1, 0}, SIN[4] = {0, 1, 0, -1};
    const int q = static_cast<int>(((static_cast<long long>(quarters) % 4) + 4) % 4);
    *c = COS[q];
    *s = SIN[q];
    return;
  }
  const double r = deg * PI / 180.0;
  *c = std::cos(r);
  *s = std::sin(r);
}

// Point on the unit sphere at ring k (0 = +y pole, rings = -y pole) and segment j.
glm::dvec3 sphere_direction(int k, int j, int rings, int segments) {
  if (k == 0) return {0, 1, 0};
  if (k == rings) return {0, -1, 0};
  const double theta = PI * k / rings;
  const double phi = 2.0 * PI * (j % segments) / segments;
  return {std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
}

// 2D cross product of (b - a) and (c - a).
double cross2(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

bool inside_triangle(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  return cross2(a, b, p) > 0 && cross2(b, c, p) > 0 && cross2(c, a, p) > 0;
}

// Whether corner `i` of the remaining polygon `ring` is an ear: convex, and no other
// remaining corner lies strictly inside the triangle it cuts off.
bool is_ear(const std::vector<glm::dvec2>& p, const std::vector<int>& ring, size_t i) {
  const size_t n = ring.size();
  const int a = ring[(i + n - 1) % n], b = ring[i], c = ring[(i + 1) % n];
  if (cross2(p[a], p[b], p[c]) <= 0) return false;
  for (int k : ring) {
    if (k == a || k == b || k == c) continue;
    if (inside_triangle(p[k], p[a], p[b], p[c])) return false;
  }
  return true;
}

struct VertexKey {
  uint32_t bits[3];
  bool operator==(const VertexKey& o) const {
    return bits[0] == o.bits[0] && bits[1] == o.bits[1] && bits[2] == o.bits[2];
  }
};

VertexKey vertex_key(const glm::vec3& p) {
  VertexKey k{};
  for (int i = 0; i < 3; ++i) {
    const float f = p[i] + 0.0f;  // -0 and +0 are one position
    std::memcpy(&k.bits[i], &f, sizeof f);
  }
  return k;
}

// A 64-bit mix (the splitmix64 finalizer, Steele et al. 2014) for the hash tables below.
uint64_t mix64(uint64_t x) {
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// For items 0..n-1: the smallest index of an item equal to each (its own when it is the
// first), or NO_PARTNER for an item skip(i) leaves out. An open-addressing hash table of
// item indices (linear probing, kept at most 3/4 full, doubled as it fills): 4 bytes an
// item for the answer and 5 to 11 bytes a distinct key for the table, no sort. `expected`
// distinct keys size the table from the start (each doubling re-hashes every key).
// PARTITIONS: equal items have equal hashes, so the items split by their hash's high half
// into independent problems, one table and one thread each, every thread walking the items
// in order and writing only its own: the same answer as one table, the tables' bytes the
// same in all, and the table's cache misses (the cost on a large mesh) shared by the threads.
template <class Hash, class Equal, class Skip>
std::vector<uint32_t> first_equal(size_t n, size_t expected, Hash&& hash, Equal&& equal, Skip&& skip) {
  constexpr uint32_t EMPTY = NO_PARTNER;
  std::vector<uint32_t> first(n, NO_PARTNER);
  const size_t parts = n < (size_t{1} << 16) ? 1 : static_cast<size_t>(thread_count(0, 2));
  parallel_for(parts, static_cast<int>(parts), [&](size_t part, int) {
    const auto mine = [&](uint64_t h) { return (h >> 32) % parts == part; };
    size_t slots = 1024;
    while (4 * (expected / parts + 1) > 3 * slots) slots *= 2;
    std::vector<uint32_t> table(slots, EMPTY);
    size_t used = 0;
    for (uint32_t i = 0; i < n; ++i) {
      if (skip(i)) continue;
      const uint64_t hi = hash(i);
      if (!mine(hi)) continue;
      if (4 * (used + 1) > 3 * table.size()) {
        std::vector<uint32_t> grown(2 * table.size(), EMPTY);
        for (const uint32_t e : table) {
          if (e == EMPTY) continue;
          size_t h = hash(e) & (grown.size() - 1);
          while (grown[h] != EMPTY) h = (h + 1) & (grown.size() - 1);
          grown[h] = e;
        }
        table.swap(grown);
      }
      for (size_t h = hi & (table.size() - 1);; h = (h + 1) & (table.size() - 1)) {
        const uint32_t e = table[h];
        if (e == EMPTY) {
          table[h] = i;
          ++used;
          first[i] = i;
          break;
        }
        if (equal(e, i)) {
          first[i] = e;
          break;
        }
      }
    }
  });
  return first;
}

}  // namespace

LocalMesh tessellate_triangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  LocalMesh m;
  push_triangle(&m, a, b, c);
  push_uvs(&m, {0, 0}, {1, 0}, {0, 1});
  return m;
}

double quad_planarity_error(const std::array<glm::dvec3, 4>& v) {
  const double size = std::max(glm::length(v[2] - v[0]), glm::length(v[3] - v[1]));
  const glm::dvec3 n = newell_normal(v.data(), 4);
  const double len = glm::length(n);
  if (!(size > 0) || !(len > ZERO_AREA_RELATIVE * size * size)) return 0;  // degenerate: no plane to miss
  const glm::dvec3 unit = n / len;
  const glm::dvec3 c = 0.25 * (v[0] + v[1] + v[2] + v[3]);
  double worst = 0;
  for (const glm::dvec3& p : v) worst = std::max(worst, std::fabs(glm::dot(p - c, unit)));
  return worst / size;
}

bool tessellate_quad(const std::array<glm::dvec3, 4>& v, LocalMesh* out) {
  glm::dvec3 n = newell_normal(v.data(), 4);
  // A symmetric bow tie has no net area; measure its triangles against the first one.
  if (glm::length(n) == 0.0) n = glm::cross(v[1] - v[0], v[2] - v[0]);
  auto agrees = [&](int a, int b, int c) { return glm::dot(glm::cross(v[b] - v[a], v[c] - v[a]), n) >= 0.0; };
  const auto push = [&](int a, int b, int c) {
    push_triangle(out, v[a], v[b], v[c]);
    push_uvs(out, quad_uv(a), quad_uv(b), quad_uv(c));
  };
  if (agrees(0, 1, 2) && agrees(0, 2, 3)) {
    push(0, 1, 2);
    push(0, 2, 3);
    return true;
  }
  if (agrees(1, 2, 3) && agrees(1, 3, 0)) {
    push(1, 2, 3);
    push(1, 3, 0);
    return true;
  }
  return false;
}

LocalMesh tessellate_box(const glm::dvec3& lo, const glm::dvec3& hi) {
  auto corner = [&](int x, int y, int z) { return glm::dvec3(x ? hi.x : lo.x, y ? hi.y : lo.y, z ? hi.z : lo.z); };
  // Each face's corners counter-clockwise seen from outside: cross(b-a, c-a) points out.
  static const int FACES[6][4][3] = {
      {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}},  // -x
      {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}},  // +x
      {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}},  // -y
      {{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}},  // +y
      {{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}},  // -z
      {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},  // +z
  };
  LocalMesh m;
  for (const auto& f : FACES) {
    glm::dvec3 q[4];
    for (int i = 0; i < 4; ++i) q[i] = corner(f[i][0], f[i][1], f[i][2]);
    push_triangle(&m, q[0], q[1], q[2]);
    push_uvs(&m, quad_uv(0), quad_uv(1), quad_uv(2));
    push_triangle(&m, q[0], q[2], q[3]);
    push_uvs(&m, quad_uv(0), quad_uv(2), quad_uv(3));
  }
  return m;
}

int sphere_rings(int segments) { return std::max(2, segments / 2); }

size_t sphere_triangle_count(int segments) {
  // Two pole caps of `segments` triangles, two triangles per cell of the other bands.
  return 2 * static_cast<size_t>(segments) * static_cast<size_t>(sphere_rings(segments) - 1);
}

LocalMesh tessellate_sphere(const glm::dvec3& center, double radius, int segments) {
  const int rings = sphere_rings(segments);
  LocalMesh m;
  m.positions.reserve(3 * sphere_triangle_count(segments));
  m.normals.reserve(3 * sphere_triangle_count(segments));
  m.uvs.reserve(3 * sphere_triangle_count(segments));
  // Latitude-longitude uvs: u = j / segments around from +x towards +z (1 on the seam's
  // far side), v = 1 at the +y pole down to 0 at the -y pole.
  auto corner = [&](int k, int j) {
    const glm::dvec3 d = sphere_direction(k, j, rings, segments);
    m.positions.push_back(center + radius * d);
    m.normals.push_back(d);
    m.uvs.emplace_back(static_cast<double>(j) / segments, 1.0 - static_cast<double>(k) / rings);
  };
  // Around +x on the equator, j grows towards +z and k towards -y, so (k,j), (k,j+1),
  // (k+1,j) winds counter-clockwise seen from outside.
  for (int k = 0; k < rings; ++k) {
    for (int j = 0; j < segments; ++j) {
      if (k > 0) {  // the triangle touching ring k (absent at the +y pole)
        corner(k, j);
        corner(k, j + 1);
        corner(k + 1, j);
      }
      if (k + 1 < rings) {  // the triangle touching ring k+1 (absent at the -y pole)
        corner(k, j + 1);
        corner(k + 1, j + 1);
        corner(k + 1, j);
      }
    }
  }
  return m;
}

std::vector<std::array<int, 3>> triangulate_polygon(const std::vector<glm::dvec3>& corners) {
  const int n = static_cast<int>(corners.size());
  std::vector<std::array<int, 3>> out;
  if (n < 3) return out;
  // Project onto the polygon's plane with a frame (u, v, normal), so it runs counter-clockwise.
  const glm::dvec3 normal = newell_normal(corners.data(), corners.size());
  std::vector<int> ring(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) ring[static_cast<size_t>(i)] = i;
  if (n > 3 && glm::length(normal) > 0.0) {
    const glm::dvec3 w = glm::normalize(normal);
    const glm::dvec3 helper = std::fabs(w.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(helper, w));
    const glm::dvec3 v = glm::cross(w, u);
    std::vector<glm::dvec2> p;
    p.reserve(corners.size());
    for (const glm::dvec3& c : corners) p.emplace_back(glm::dot(c, u), glm::dot(c, v));
    while (ring.size() > 3) {
      size_t ear = ring.size();
      for (size_t i = 0; i < ring.size() && ear == ring.size(); ++i) {
        if (is_ear(p, ring, i)) ear = i;
      }
      if (ear == ring.size()) break;  // no ear: numerically degenerate, fan the rest
      const size_t m = ring.size();
      out.push_back({ring[(ear + m - 1) % m], ring[ear], ring[(ear + 1) % m]});
      ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(ear));
    }
  }
  for (size_t i = 1; i + 1 < ring.size(); ++i) out.push_back({ring[0], ring[i], ring[i + 1]});
  return out;
}

AffineMap make_affine_map(const Transform& t) {
  double cx, sx, cy, sy, cz, sz;
  cos_sin_deg(t.rotate_deg.x, &cx, &sx);
  cos_sin_deg(t.rotate_deg.y, &cy, &sy);
  cos_sin_deg(t.rotate_deg.z, &cz, &sz);
  // Right-handed rotations, GLM column-major: each dmat3 argument triple is a column.
  const glm::dmat3 rx(1, 0, 0, 0, cx, sx, 0, -sx, cx);
  const glm::dmat3 ry(cy, 0, -sy, 0, 1, 0, sy, 0, cy);
  const glm::dmat3 rz(cz, sz, 0, -sz, cz, 0, 0, 0, 1);
  const glm::dmat3 s(t.scale.x, 0, 0, 0, t.scale.y, 0, 0, 0, t.scale.z);
  AffineMap m;
  m.linear = rz * ry * rx * s;  // scale first, then x, y, z
  m.offset = t.translate;
  // Normals transform by the inverse transpose (e.g. pbrt-v4 Transform::ApplyNormal).
  m.normal_matrix = glm::transpose(glm::inverse(m.linear));
  m.mirrors = glm::determinant(m.linear) < 0.0;
  return m;
}

bool is_zero_area(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const double longest2 = std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
  const double twice_area = glm::length(glm::cross(b - a, c - a));
  return !(twice_area > ZERO_AREA_RELATIVE * longest2) || !std::isfinite(longest2);
}

namespace {

// Local triangle t, mapped by m, written to soup place `at` (its object id already there);
// false, nothing written, for a triangle the renderer would not see whole (not finite, or
// of zero area). `order`: the corners' order (reversed by a mirroring map).
bool put_triangle(const LocalMesh& local, const AffineMap& m, const int order[3], size_t t, uint32_t material,
                  bool store_uvs, size_t at, TriangleSoup* soup) {
  glm::vec3 f[3];
  glm::dvec3 p[3];
  for (int k = 0; k < 3; ++k) {
    f[k] = to_float(m.point(local.position(3 * t + static_cast<size_t>(order[k]))));
    p[k] = glm::dvec3(f[k]);  // judge the triangle the renderer will see
  }
  if (!finite3(p[0]) || !finite3(p[1]) || !finite3(p[2]) || is_zero_area(p[0], p[1], p[2])) return false;
  const glm::dvec3 flat = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
  glm::dvec3 n[3] = {flat, flat, flat};
  if (!local.normals.empty()) {
    bool smooth = true;
    for (int k = 0; k < 3 && smooth; ++k) {
      const glm::dvec3 w = m.normal_matrix * local.normal(3 * t + static_cast<size_t>(order[k]));
      const double len = glm::length(w);
      smooth = std::isfinite(len) && len > 0.0;
      if (smooth) n[k] = w / len;
    }
    if (!smooth) n[0] = n[1] = n[2] = flat;
  }
  for (size_t k = 0; k < 3; ++k) {
    soup->positions[3 * at + k] = f[k];
    soup->normals[3 * at + k] = glm::vec3(n[k]);
    if (store_uvs) soup->uvs[3 * at + k] = glm::vec2(local.uv(3 * t + static_cast<size_t>(order[k])));
  }
  const int mat = local.material.empty() ? -1 : local.material[t];
  soup->material_id[at] = mat < 0 ? material : static_cast<uint32_t>(mat);
  return true;
}

// Moves the kept triangles of places first, first + 1, ... down over the dropped ones, in
// order, and cuts the soup after them.
void close_up(const std::vector<uint8_t>& kept, size_t first, bool store_uvs, TriangleSoup* soup) {
  size_t to = first;
  for (size_t t = 0; t < kept.size(); ++t) {
    if (!kept[t]) continue;
    const size_t from = first + t;
    if (to != from) {
      std::copy_n(&soup->positions[3 * from], 3, &soup->positions[3 * to]);
      std::copy_n(&soup->normals[3 * from], 3, &soup->normals[3 * to]);
      if (store_uvs) std::copy_n(&soup->uvs[3 * from], 3, &soup->uvs[3 * to]);
      soup->material_id[to] = soup->material_id[from];
    }
    ++to;
  }
  soup->positions.resize(3 * to);
  soup->normals.resize(3 * to);
  if (store_uvs) soup->uvs.resize(3 * to);
  soup->object_id.resize(to);
  soup->material_id.resize(to);
}

}  // namespace

size_t append_triangles(const LocalMesh& local, const AffineMap& m, uint32_t object_id, uint32_t material,
                        TriangleSoup* soup, int threads) {
  // A mirroring transform reverses the winding; swapping b and c restores the sense of
  // the geometric normal.
  const int order[3] = {0, m.mirrors ? 2 : 1, m.mirrors ? 1 : 2};
  // Room for the whole object at once and half as much again: a large mesh is never copied
  // while it grows, nor by the small objects after it (peak memory).
  const size_t need = soup->object_id.size() + local.triangle_count();
  if (soup->object_id.capacity() < need) {
    const size_t room = std::max(need + need / 2, 2 * soup->object_id.size());  // untouched room costs no memory
    soup->positions.reserve(3 * room);
    soup->normals.reserve(3 * room);
    if (!local.uvs.empty() || !soup->uvs.empty()) soup->uvs.reserve(3 * room);
    soup->object_id.reserve(room);
    soup->material_id.reserve(room);
  }
  // The first object with texture coordinates gives the objects before it (0, 0).
  // (Tested on the soup's size, not its emptiness: the first object of all has no objects before it.)
  const bool store_uvs = !local.uvs.empty() || !soup->uvs.empty();
  if (store_uvs && soup->uvs.size() < soup->positions.size()) soup->uvs.resize(soup->positions.size(), glm::vec2(0.0f));
  // Triangle t is written to place first + t, on up to `threads` threads, each a run of
  // triangles; then, if some were dropped, the kept ones close up in order: the same soup
  // as one thread appending the kept triangles one by one.
  const size_t first = soup->object_id.size(), count = local.triangle_count();
  soup->positions.resize(3 * (first + count));
  soup->normals.resize(3 * (first + count));
  if (store_uvs) soup->uvs.resize(3 * (first + count));
  soup->object_id.resize(first + count, object_id);
  soup->material_id.resize(first + count);
  std::vector<uint8_t> kept(count);
  parallel_for_runs(count, size_t{1} << 14, threads, [&](size_t t) {
    kept[t] = put_triangle(local, m, order, t, material, store_uvs, first + t, soup) ? 1 : 0;
  });
  const size_t dropped = static_cast<size_t>(std::count(kept.begin(), kept.end(), 0));
  if (dropped > 0) close_up(kept, first, store_uvs, soup);
  return dropped;
}

namespace {

// The corner after corner c of its triangle (corners 3t, 3t + 1, 3t + 2).
uint32_t next_corner(uint32_t c) { return c - c % 3 + (c % 3 + 1) % 3; }

}  // namespace

std::vector<uint32_t> edge_partners(const TriangleSoup& soup, size_t first, size_t count) {
  ABCUBE_CHECK(3 * (first + count) <= soup.positions.size() && 3 * count < NO_PARTNER - 1, "triangle range");
  const glm::vec3* p = soup.positions.data() + 3 * first;
  const uint32_t* object = soup.object_id.data() + first;
  // Edge ids: the first half-edge of the same object whose two end positions are the same
  // (bit for bit, -0 = +0), in either order. Compared by position, not through per-corner
  // vertex ids: no second array of 4 bytes a corner beside the answer (peak memory).
  const auto vertex_hash = [&](uint32_t c) {
    const VertexKey k = vertex_key(p[c]);
    return mix64((uint64_t{k.bits[0]} << 32 | k.bits[1]) ^ mix64(uint64_t{k.bits[2]} << 32 | object[c / 3]));
  };
  const auto same_vertex = [&](uint32_t a, uint32_t b) { return vertex_key(p[a]) == vertex_key(p[b]); };
  // Two half-edges an edge on a closed mesh, a few more edges on an open one's border.
  std::vector<uint32_t> partner = first_equal(
      3 * count, 3 * count / 2 + 3 * count / 64,
      [&](uint32_t h) {
        const uint64_t a = vertex_hash(h), b = vertex_hash(next_corner(h));
        return mix64(std::min(a, b) ^ mix64(std::max(a, b)));
      },
      [&](uint32_t a, uint32_t b) {
        if (object[a / 3] != object[b / 3]) return false;
        const uint32_t a2 = next_corner(a), b2 = next_corner(b);
        return (same_vertex(a, b) && same_vertex(a2, b2)) || (same_vertex(a, b2) && same_vertex(a2, b));
      },
      [&](uint32_t h) { return same_vertex(h, next_corner(h)); });
  // Pair each half-edge with the first of its edge; a third one unpairs the edge. In place:
  // entry h holds h's edge id until h is reached, its partner after (every write goes to
  // an entry at or before h, already reached).
  constexpr uint32_t SHARED = NO_PARTNER - 1;  // an edge of three or more half-edges
  for (uint32_t h = 0; h < partner.size(); ++h) {
    const uint32_t f = partner[h];
    partner[h] = NO_PARTNER;
    if (f == NO_PARTNER || f == h) continue;
    if (partner[f] == NO_PARTNER) {
      partner[f] = h;
      partner[h] = f;
    } else {
      if (partner[f] != SHARED) partner[partner[f]] = SHARED;
      partner[f] = partner[h] = SHARED;
    }
  }
  for (uint32_t& q : partner) q = q == SHARED ? NO_PARTNER : q;
  return partner;
}

namespace {

// Whether triangles [first, first + count) may be closed: the sum of (b - a) x (c - a) over a
// closed, consistently oriented surface is exactly zero (each edge u -> v's u x v meets its
// v x u), so a sum larger than its rounding can reach rules a closed surface out. In double,
// each term is within 7 unit roundoffs (2^-53) of |b - a| |c - a| (two subtractions, two
// products, their difference) and the running sum adds at most `count` more of the sum of
// those: the threshold, (count + 8) 2^-52 of it, is twice that. Open meshes (terrains,
// scans, planes) are ruled out here, in one pass over their positions with no table.
bool may_be_closed(const TriangleSoup& soup, size_t first, size_t count) {
  glm::dvec3 sum(0.0);
  double bound = 0.0;
  for (size_t t = first; t < first + count; ++t) {
    const glm::dvec3 a(soup.positions[3 * t]);
    const glm::dvec3 u = glm::dvec3(soup.positions[3 * t + 1]) - a;
    const glm::dvec3 v = glm::dvec3(soup.positions[3 * t + 2]) - a;
    sum += glm::cross(u, v);
    bound += glm::length(u) * glm::length(v);
  }
  const double ulp = std::ldexp(1.0, -52);
  const double slack = (static_cast<double>(count) + 8.0) * ulp * bound;
  return std::fabs(sum.x) <= slack && std::fabs(sum.y) <= slack && std::fabs(sum.z) <= slack;
}

}  // namespace

bool is_closed_surface(const TriangleSoup& soup, size_t first, size_t count) {
  if (count == 0 || !may_be_closed(soup, first, count)) return false;
  const std::vector<uint32_t> partner = edge_partners(soup, first, count);
  const glm::vec3* p = soup.positions.data() + 3 * first;
  for (uint32_t h = 0; h < partner.size(); ++h) {
    // Every edge shared by exactly two half-edges running in opposite directions.
    const uint32_t q = partner[h];
    if (q == NO_PARTNER || !(vertex_key(p[h]) == vertex_key(p[next_corner(q)]))) return false;
  }
  return true;
}

double signed_volume(const TriangleSoup& soup, size_t first, size_t count) {
  if (count == 0) return 0.0;
  const glm::dvec3 o(soup.positions[3 * first]);  // any origin; near the mesh for precision
  double six_v = 0;
  for (size_t t = first; t < first + count; ++t) {
    const glm::dvec3 a = glm::dvec3(soup.positions[3 * t]) - o;
    const glm::dvec3 b = glm::dvec3(soup.positions[3 * t + 1]) - o;
    const glm::dvec3 c = glm::dvec3(soup.positions[3 * t + 2]) - o;
    six_v += glm::dot(a, glm::cross(b, c));
  }
  return six_v / 6.0;
}

void flip_winding(TriangleSoup* soup, size_t first, size_t count) {
  for (size_t t = first; t < first + count; ++t) {
    std::swap(soup->positions[3 * t + 1], soup->positions[3 * t + 2]);
    std::swap(soup->normals[3 * t + 1], soup->normals[3 * t + 2]);
    if (!soup->uvs.empty()) std::swap(soup->uvs[3 * t + 1], soup->uvs[3 * t + 2]);
    const glm::vec3 a = soup->positions[3 * t];
    const glm::vec3 g = glm::cross(soup->positions[3 * t + 1] - a, soup->positions[3 * t + 2] - a);
    for (int k = 0; k < 3; ++k) {
      glm::vec3& n = soup->normals[3 * t + static_cast<size_t>(k)];
      if (glm::dot(n, g) < 0.0f) n = -n;
    }
  }
}

}  // namespace abcube
