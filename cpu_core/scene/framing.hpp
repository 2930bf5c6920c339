// Framing (docs/scene-format.md "Framing", "camera.frame"): a camera placed to see the
// whole scene from a given direction, and the lights a scene without any gets.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "base/bounds.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

// The view direction "frame" uses when none is given: from the front (+z), right (+x) and
// above, towards -z: a three-quarter view, so that a flat model in any axis plane is seen
// face on enough (from straight ahead, a model in a plane x = c is seen edge on).
inline const glm::dvec3 DEFAULT_FRAME_DIRECTION{-0.5, -0.4, -1.0};

// `camera` (its fov_y, width, height and up kept) looking along `direction` at the centre of
// `bounds`, from the nearest distance at which all 8 corners of the bounds project inside
// the image with a 5% margin on each side (and lie in front of the camera, so the camera is
// outside the bounds). Empty bounds frame the cube [-1, 1]^3. An `up` parallel
// to `direction` is replaced by -z (looking down) or +z (looking up). `direction` must be
// nonzero.
Camera frame_camera(const Bounds& bounds, const glm::dvec3& direction, Camera camera);

// Lights for a framed scene that has none: a key light (0.8, casting shadows) above and to
// the left of the camera, and a fill light (0.25, no shadows) to its right, both at twice
// the camera's distance from the centre of the bounds.
std::vector<PointLight> frame_lights(const Bounds& bounds, const Camera& camera);

}  // namespace abcube
