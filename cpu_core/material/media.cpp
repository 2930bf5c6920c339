// NESTED DIELECTRICS (media.hpp): the stack, the priority and the crossing sets.
#include "material/media.hpp"
#include "scene/tie_rule.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace abcube {

namespace {
constexpr uint32_t AIR = std::numeric_limits<uint32_t>::max();

// THE TIE RULE (scene/tie_rule.hpp): of two coincident triangles, the one ranking above.
uint32_t tie_winner(const TriangleSoup& soup, uint32_t a, uint32_t b) { return ranks_above(soup, b, a) ? b : a; }
}  // namespace

double scene_scale(const SceneData& scene) {
  const Bounds b = scene.bounds();
  if (b.empty()) return 0.0;
  const glm::dvec3 m = glm::max(glm::abs(b.lo), glm::abs(b.hi));
  return std::max(m.x, std::max(m.y, m.z)) + glm::length(b.hi - b.lo);
}

double coincident_tolerance(const glm::dvec3& p, double scene_scale) {
  const double m = std::fmax(std::fabs(p.x), std::fmax(std::fabs(p.y), std::fabs(p.z)));
  return COINCIDENT_REL * (m + scene_scale);
}

bool MediumStack::contains(uint32_t o) const {
  for (int k = 0; k < size; ++k) {
    if (object[static_cast<size_t>(k)] == o) return true;
  }
  return false;
}

void MediumStack::add(uint32_t o, double n) {
  if (size == MEDIA_STACK_MAX || contains(o)) return;
  object[static_cast<size_t>(size)] = o;
  ior[static_cast<size_t>(size)] = n;
  ++size;
}

void MediumStack::remove(uint32_t o) {
  for (int k = 0; k < size; ++k) {
    if (object[static_cast<size_t>(k)] != o) continue;
    for (int j = k + 1; j < size; ++j) {
      object[static_cast<size_t>(j - 1)] = object[static_cast<size_t>(j)];
      ior[static_cast<size_t>(j - 1)] = ior[static_cast<size_t>(j)];
    }
    --size;
    return;
  }
}

Media::Media(const SceneData& scene) : scene_(&scene), scale_(scene_scale(scene)) {
  const TriangleSoup& soup = *scene.triangles;
  bounds_.resize(scene.objects.size());
  volume_.resize(scene.objects.size(), 0.0);
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const SceneObject& obj = scene.objects[o];
    for (size_t t = obj.first_triangle; t < static_cast<size_t>(obj.first_triangle) + obj.triangle_count; ++t) {
      for (int k = 0; k < 3; ++k) bounds_[o].extend(glm::dvec3(soup.positions[3 * t + static_cast<size_t>(k)]));
    }
    if (!bounds_[o].empty()) {
      const glm::dvec3 e = bounds_[o].hi - bounds_[o].lo;
      volume_[o] = e.x * e.y * e.z;
    }
  }
}

bool Media::is_medium(uint32_t tri) const {
  const TriangleSoup& soup = *scene_->triangles;
  return scene_->objects[soup.object_id[tri]].closed && scene_->materials[soup.material_id[tri]].transmit > 0.0;
}

bool Media::outranks(uint32_t a, uint32_t b) const {
  if (volume_[a] != volume_[b]) return volume_[a] < volume_[b];
  return a > b;  // the tie rule: listed later wins
}

uint32_t Media::top(const MediumStack& s) const {
  uint32_t best = AIR;
  for (int k = 0; k < s.size; ++k) {
    const uint32_t o = s.object[static_cast<size_t>(k)];
    if (best == AIR || outranks(o, best)) best = o;
  }
  return best;
}

double Media::index(const MediumStack& s) const {
  const uint32_t t = top(s);
  for (int k = 0; k < s.size; ++k) {
    if (s.object[static_cast<size_t>(k)] == t) return s.ior[static_cast<size_t>(k)];
  }
  return 1.0;
}

bool Media::bounds_meet(uint32_t a, uint32_t b) const {
  const Bounds& x = bounds_[a];
  const Bounds& y = bounds_[b];
  if (x.empty() || y.empty()) return false;
  const double tol = 2.0 * COINCIDENT_REL * scale_;
  for (int k = 0; k < 3; ++k) {
    if (x.lo[k] > y.hi[k] + tol || y.lo[k] > x.hi[k] + tol) return false;
  }
  return true;
}

Interface Media::resolve(const MediumStack& before, const MediumCrossing* c, size_t count) const {
  const TriangleSoup& soup = *scene_->triangles;
  Interface r;
  r.before = before;
  // The crossings in order along the ray; at equal t a leave before an entry.
  std::vector<MediumCrossing> order(c, c + count);
  std::sort(order.begin(), order.end(), [](const MediumCrossing& a, const MediumCrossing& b) {
    return a.t != b.t ? a.t < b.t : a.leaving > b.leaving;
  });
  MediumStack from = before, now = before;
  bool plain = false;
  uint32_t plain_tri = 0, any_tri = order.front().triangle;
  bool plain_leaving = false;
  for (const MediumCrossing& k : order) {
    any_tri = tie_winner(soup, any_tri, k.triangle);
    if (!is_medium(k.triangle)) {
      if (!plain || tie_winner(soup, plain_tri, k.triangle) == k.triangle) {
        plain_tri = k.triangle;
        plain_leaving = k.leaving;
      }
      plain = true;
      continue;
    }
    const uint32_t o = soup.object_id[k.triangle];
    const double n = scene_->materials[soup.material_id[k.triangle]].ior;
    if (!k.leaving) {
      now.add(o, n);
    } else if (now.contains(o)) {
      now.remove(o);
    } else {
      from.add(o, n);  // left without having been entered: it was around the ray (THE STACK)
    }
  }
  r.after = now;
  if (plain) {
    // A plain surface stops the ray; an open refractive one bends between air and its ior.
    const double n = scene_->materials[soup.material_id[plain_tri]].ior;
    r.triangle = plain_tri;
    r.n_from = plain_leaving ? n : 1.0;
    r.n_to = plain_leaving ? 1.0 : n;
    r.before.passes = r.after.passes = 0;
    return r;
  }
  r.triangle = any_tri;
  r.n_from = index(from);
  r.n_to = index(now);
  if (top(from) == top(now)) {
    r.pass = true;
    r.after.passes = before.passes + 1;
    return r;
  }
  r.before.passes = r.after.passes = 0;
  return r;
}

}  // namespace abcube
