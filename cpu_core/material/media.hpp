// NESTED DIELECTRICS: touching and nested transparent objects, decided the same way by the
// exact tracer (raytrace.hpp) and the map searches (map_shading.hpp); the model is Schmidt &
// Budge 2002, "Simple nested dielectrics in ray traced images", with one priority rule of
// ours. MEDIA: closed objects crossed on a kt > 0 triangle. THE STACK: the media a ray is
// inside. PRIORITY: the smaller bounding box wins, then the later object. INTERFACES: the
// surfaces crossed within coincident_tolerance form one crossing set, which is either no
// interface or one interface n_from -> n_to, shaded with its tie winner (scene/tie_rule.hpp).
// docs/design/media.md has the whole argument.
// also gathers surfaces a few ulps of rounding apart after a transform, as one interface.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "base/bounds.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

// Deepest nesting a ray keeps track of; a medium entered beyond it is not recorded (a ray
// inside 8 media at once).
constexpr int MEDIA_STACK_MAX = 8;
// Two surfaces crossed within this share of (max |P_i| + scene_scale) of each other are
// one crossing set (1000 times the self-intersection offset of shading.hpp: far above the
// rounding of float vertices shared by two objects, far below any modelled thickness).
constexpr double COINCIDENT_REL = 1e-6;
// Surfaces a ray may pass unshaded (no interface) before it is dropped (background): a
// guard against a loop, never reached by a closed scene.
constexpr int MEDIA_MAX_PASSES = 64;

// Largest absolute vertex coordinate plus the diagonal of the vertex bounds (0 when empty).
double scene_scale(const SceneData& scene);

// The coincident tolerance at point p (INTERFACES, docs/design/media.md), world units.
double coincident_tolerance(const glm::dvec3& p, double scene_scale);

struct MediumStack {
  std::array<uint32_t, MEDIA_STACK_MAX> object{};
  std::array<double, MEDIA_STACK_MAX> ior{};
  int size = 0;
  int passes = 0;  // surfaces passed without an interface since the last one
  bool empty() const { return size == 0; }
  bool contains(uint32_t o) const;
  void add(uint32_t o, double n);  // no effect when present or full
  void remove(uint32_t o);
};

// One surface crossed: a triangle, and whether the ray leaves (along the outward normal).
struct MediumCrossing {
  uint32_t triangle = 0;
  bool leaving = false;
  double t = 0;  // along the ray, for the order
};

// What a crossing set is (INTERFACES, docs/design/media.md).
struct Interface {
  uint32_t triangle = 0;  // the surface shaded
  bool pass = false;      // no interface: go on straight, unshaded, same depth
  double n_from = 1.0, n_to = 1.0;
  MediumStack before, after;
};

class Media {
 public:
  explicit Media(const SceneData& scene);
  Media(const Media&) = delete;
  Media& operator=(const Media&) = delete;

  // Is triangle `tri` a medium's surface (MEDIA, docs/design/media.md)?
  bool is_medium(uint32_t tri) const;
  // PRIORITY (docs/design/media.md): does object a outrank object b?
  bool outranks(uint32_t a, uint32_t b) const;
  // The medium a ray with this stack travels in (UINT32_MAX: air) and its index.
  uint32_t top(const MediumStack& s) const;
  double index(const MediumStack& s) const;
  // Do the bounding boxes of two objects meet (within the coincident tolerance)? A surface
  // a ray inside medium `a` crosses before leaving it belongs to `a` or to such an object.
  bool bounds_meet(uint32_t a, uint32_t b) const;
  double scale() const { return scale_; }
  double tolerance(const glm::dvec3& p) const { return coincident_tolerance(p, scale_); }

  // The crossing set `c` (any order; at least one) met by a ray carrying `before`.
  Interface resolve(const MediumStack& before, const MediumCrossing* c, size_t count) const;

 private:
  const SceneData* scene_;
  std::vector<Bounds> bounds_;
  std::vector<double> volume_;
  double scale_ = 0;
};

}  // namespace abcube
