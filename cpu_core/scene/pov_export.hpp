// Writing a scene as a POV-Ray 3.7 scene, so an independent ray tracer can check ours.
// MAPPING: z negated (POV-Ray is left-handed) with POV-Ray's default left-handed camera, so
// the picture is not mirrored; the vertical field of view exact; linear 16-bit output; one
// mesh2 per (object, material) with the soup's vertex normals. WHAT MATCHES EXACTLY (the
// comparison test stays inside it): ambient, Lambert, mirror reflection, refraction on closed
// objects, total internal reflection, hard shadows through transmitting blockers, coverage
// transparency of a plain material. RESIDUAL DIFFERENCES (Phong highlights among them, so the
// comparison uses ks = 0): docs/design/pov-export.md lists them with the whole mapping.
#pragma once
#include <string>

#include "scene/scene_data.hpp"

namespace abcube {

// The scene as POV-Ray 3.7 scene description text (the MAPPING of docs/design/pov-export.md).
std::string export_pov(const SceneData& scene);

}  // namespace abcube
