// NESTED DIELECTRICS (issue 12 part 2): touching and nested transparent objects, decided
// the same way by the exact tracer (raytrace.hpp) and the map searches (map_shading.hpp).
//
// The model is Schmidt & Budge 2002, "Simple nested dielectrics in ray traced images"
// (journal of graphics tools 7(2)), with one priority rule of ours:
//
// MEDIA. A medium is a closed object (SceneObject::closed) crossed on a triangle whose
// material has kt > 0; its index is that material's ior. Every other surface (opaque, or
// open: a single refractive quad) is a plain surface, as before this model: an open
// refractive surface bends between air and its ior by its facing (shading.hpp transmission).
//
// THE STACK. A ray carries the media it is inside (MediumStack, in the order entered; a
// camera ray starts with none: the camera is in air). Crossing a medium's surface against
// its outward geometric normal enters it, along the normal leaves it. Leaving a medium the
// stack does not hold (the camera inside a glass, or an entry lost to rounding) is taken as
// if the ray had been inside it: that reproduces the single-object rule n -> 1.
//
// PRIORITY. Where a ray is inside several media at once, the medium it travels in is the
// one of highest priority: an object outranks another iff its bounding box has the smaller
// volume, and at equal volume iff it is listed later in the scene (the tie rule,
// scene/tie_rule.hpp). So a medium nested inside another (its bounds inside the other's)
// always wins: a ray inside a glass sphere that meets a water sphere inside it enters the
// water, whatever the order of the objects in the file. Overlapping media (a modelling
// choice, not nesting) are decided by the same rule: the smaller wins in the overlap.
//
// INTERFACES. A ray meets the surfaces along it one CROSSING SET at a time: the first
// surface crossed and every other surface crossed within coincident_tolerance of it (a
// face shared by two touching objects is two coincident triangles; a ray through a shared
// edge of one object crosses two). A crossing set with a plain surface stops the ray at that
// surface (a glass box standing on an opaque floor: the ray inside the glass sees the
// floor); the plain surface shaded is the tie winner among them. A set of medium crossings
// only updates the stack (in order along the ray, a leave before an entry at equal t): the medium
// before is the top of the stack before, the medium after the top of the stack after, and
//   - the same medium on both sides (a lower-priority medium's surface inside a higher
//     one's): NO interface, the ray goes on straight, unshaded, at the same depth (Schmidt &
//     Budge's false intersection);
//   - different media: ONE interface from one medium into the other, shaded with the
//     material of the tie winner among the set's triangles, refracted by Snell with the
//     ratio n_from / n_to of the two media's indices (air is 1), not n / 1. A shared face
//     between glass and water bends glass -> water once; between two glass boxes it does
//     not bend at all.
// Reflected rays, and the transmitted weight under total internal reflection, keep the
// stack before the set; transmitted rays and coverage-continued rays (opacity < 1) take the
// stack after it. Shadow rays are unchanged (every surface crossed filters the light).
//
// WHAT THE TIE RULE DECIDES HERE. Which of a crossing set's triangles is shaded: the one
// ranking highest by the project's single tie rule (scene/tie_rule.hpp ranks_above: the
// object listed later, then the higher triangle). The crossing set's own window,
// coincident_tolerance, is wider than the rule's tie_bound (2^-22 of the coordinates): it
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

// The coincident tolerance at point p (INTERFACES above), world units.
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

// What a crossing set is (INTERFACES above).
struct Interface {
  uint32_t triangle = 0;     // the surface shaded
  bool pass = false;         // no interface: go on straight, unshaded, same depth
  double n_from = 1.0, n_to = 1.0;
  MediumStack before, after;
};

class Media {
 public:
  explicit Media(const SceneData& scene);
  Media(const Media&) = delete;
  Media& operator=(const Media&) = delete;

  // Is triangle `tri` a medium's surface (MEDIA above)?
  bool is_medium(uint32_t tri) const;
  // PRIORITY above: does object a outrank object b?
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
