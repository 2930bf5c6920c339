// The shadow volume of a point light (course notes 3.3; Everitt & Kilgard 2002, "Practical
// and Robust Stenciled Shadow Volumes"): what the gpu method counts, per camera sample, to
// decide whether an opaque blocker lies between the sample's point and the light, exactly
// where shadow maps compare depths at a texel's resolution. Every blocker triangle bounds the
// closed, outward-oriented prism of points behind it (near cap, far cap at infinity, one side
// per edge), so depth-fail counting gives the number of prisms holding a surface point
// wherever the eye is. Sides that cancel in pairs are left out, and a closed object with the
// light outside casts from its triangles facing the light alone.
// docs/design/shadow-volume.md has the whole argument.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/gpu_limits.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

struct ShadowVolumeVertex {
  glm::vec4 position;  // w = 1: a point; w = 0: a direction from the light (a point at infinity)
  uint32_t object;     // the caster's object (THE TIE RULE's depth scaling of near caps, tie_rule.hpp)
  uint32_t reversed;   // 1: the face's outward orientation is opposite to its winding
};

// A volume is kept as small as the GL and the clipping need: copies of what the scene
// already has would cost more memory a light than the scene's own triangles. Its near caps
// are the scene's own triangles, drawn from the scene's vertex buffer with a code each
// (scene.vert, VOLUME_CAPS); its far caps are made from the soup when they are clipped; only
// its sides, along the edges that do not cancel, are stored.
enum CapCode : uint8_t {
  NO_CAP = 0,        // the triangle casts nothing in this volume
  CAP = 1,           // it casts; its prism is oriented as it is wound
  CAP_REVERSED = 2,  // it casts; its prism's outward orientation is opposite to its winding
};

struct ShadowVolume {
  glm::dvec3 light{0.0};
  std::vector<uint8_t> caps;                      // CapCode per soup triangle
  std::vector<ShadowVolumeVertex> side_vertices;  // the sides: triangles, three vertices each
  uint64_t blockers = 0;                          // triangles that cast (prisms)
  uint64_t sides = 0;                             // side quads kept
  uint64_t sides_cancelled = 0;                   // side quads left out in cancelling pairs
  uint64_t facing_away_left_out = 0;              // closed objects' triangles facing away from a light outside them
  uint64_t triangle_count() const { return 2 * blockers + 2 * sides; }
};

// Every face of the volume as triangles, in the order the GL counts them: per blocker its
// near cap (w = 1, the triangle's own vertices in their own order) then its far cap (w = 0),
// then the sides. For tests and tools; the render never makes this array.
std::vector<ShadowVolumeVertex> volume_triangles(const ShadowVolume& volume, const TriangleSoup& soup);

// Whether the light is strictly outside each closed object (per object; false for an open
// one): no triangle of it has its plane through the light (plane_holds_light), and its
// winding number about the light (the solid angles its outward triangles subtend, over 4 pi:
// 0 outside, 1 inside, 1/2 on its surface; van Oosterom & Strackee 1983) is below 1/2.
std::vector<uint8_t> lights_outside_closed(const SceneData& scene, const glm::dvec3& light);

// Which blockers a volume is made of: the opaque ones (blocker_transmittance 0: the
// shadow), or the translucent ones (neither 0 nor 1: glass, veils; where their count is 0
// no light is dimmed by them, elsewhere the product of their transmittances is needed).
enum class Blockers { opaque, translucent };

// The volume of the light at `light` over the scene's blockers of that kind.
ShadowVolume build_shadow_volume(const SceneData& scene, const glm::dvec3& light, Blockers kind = Blockers::opaque);

// THE FACES AT INFINITY, CLIPPED ON THE CPU. A side or a far cap of a light almost in its
// caster's plane reaches infinity nearly perpendicular to the view, or behind the eye: clip
// coordinates with w near 0 or below, which the GL's float clipper cuts with vertices off by
// far more than a sample, so a far cap covering the whole tile would miss wedges at its
// edges (and the shadow there). These faces are clipped here, in double, to the view's clip
// volume (-w <= x, y <= w, the near plane and, in a mirror's virtual view, the mirror's
// plane), then given to the GL as window-space points it need not clip again. An edge two
// faces share is cut from its endpoints in one canonical order: no crack, no overlap.
// docs/design/shadow-volume.md has the whole argument.

// The volume's faces with a corner at infinity (its far caps, made from `soup`, then its
// sides; corners: points w = 1 in world coordinates, directions w = 0) seen through
// `clip_from_relative` (the view's clip matrix applied to a point relative to `eye`, or to a
// direction), clipped as above, triangulated as fans into `out` with positions in clip
// coordinates of w = 1. `tie_step`: THE TIE RULE's depth scale (z times 1 + tie_step
// (object + 1), scene.vert). `plane` (n, d), when given: keep n . (p - eye) + d w >= 0 (a
// virtual view's mirror, relative to its eye). Returns the triangles written. Faces
// [first, first + count) only, when given: face t < soup.triangle_count() is triangle t's
// far cap (nothing when it casts none), the others the sides in order; the caller clips and
// draws a run at a time, so that neither the clipped faces nor the GL's copy of them grow
// with the whole volume.
size_t clip_faces_at_infinity(const ShadowVolume& volume, const TriangleSoup& soup,
                              const glm::dmat4& clip_from_relative, const glm::dvec3& eye, double tie_step,
                              const glm::dvec4* plane, std::vector<ShadowVolumeVertex>* out, size_t first = 0,
                              size_t count = SIZE_MAX);
// The faces clip_faces_at_infinity numbers: the soup's triangles, then the side triangles.
inline size_t faces_at_infinity(const ShadowVolume& volume) {
  return volume.caps.size() + volume.side_vertices.size() / 3;
}

}  // namespace abcube
