// Framing (cpu_core/scene/framing.cpp): the camera that sees the whole scene, known positions,
// "frame": "all" in a scene file.
#include "scene_load_fixtures.hpp"

namespace abcube {
namespace {

using namespace scene_test;

// ---- Framing -----------------------------------------------------------------------------

// The pixel a point projects to (x right, y down), through the camera's own frame.
glm::dvec2 project(const Camera& c, const glm::dvec3& p) {
  const glm::dvec3 f = glm::normalize(c.look_at - c.position);
  const glm::dvec3 r = glm::normalize(glm::cross(f, c.up));
  const glm::dvec3 u = glm::cross(r, f);
  const glm::dvec3 q = p - c.position;
  const double t = std::tan(c.fov_y_deg * 3.14159265358979323846 / 360.0);
  const double aspect = static_cast<double>(c.width) / c.height;
  const double x = glm::dot(q, r) / (glm::dot(q, f) * t * aspect), y = glm::dot(q, u) / (glm::dot(q, f) * t);
  return {(x + 1) * 0.5 * c.width, (1 - y) * 0.5 * c.height};
}

TEST(Framing, TheBoundsFitTheImageFromTheGivenDirection) {
  Bounds b;
  b.extend(glm::dvec3(-1, 0, -3));
  b.extend(glm::dvec3(3, 2, 1));
  for (const glm::dvec3& dir :
       {glm::dvec3(0, -0.35, -1), glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(-1, -2, 3)}) {
    Camera c;
    c.width = 320;
    c.height = 200;
    c = frame_camera(b, dir, c);
    EXPECT_EQ(c.look_at, glm::dvec3(1, 1, -1));
    EXPECT_NEAR(glm::length(glm::normalize(c.look_at - c.position) - glm::normalize(dir)), 0.0, 1e-12);
    bool outside = false;
    for (int i = 0; i < 3; ++i) outside = outside || c.position[i] < b.lo[i] || c.position[i] > b.hi[i];
    EXPECT_TRUE(outside) << "camera inside the bounds";
    double widest_x = 0, widest_y = 0;
    for (int k = 0; k < 8; ++k) {
      const glm::dvec3 p(k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z);
      const glm::dvec2 px = project(c, p);
      EXPECT_GE(px.x, 0.0);
      EXPECT_LE(px.x, 320.0);
      EXPECT_GE(px.y, 0.0);
      EXPECT_LE(px.y, 200.0);
      widest_x = std::max(widest_x, std::fabs(px.x - 160) / 160);
      widest_y = std::max(widest_y, std::fabs(px.y - 100) / 100);
    }
    // Fitted, not merely inside: one side reaches the 5% margin.
    EXPECT_NEAR(std::max(widest_x, widest_y), 1 / 1.05, 1e-9);
  }
}

TEST(Framing, KnownCameraPosition) {
  // A cube of side 2 at the origin seen along -z with a 90-degree square view: the nearest
  // face (z = 1) has its corners at |x| = |y| = 1, so distance d satisfies 1 = (d - 1) tan(45) / 1.05.
  Bounds b;
  b.extend(glm::dvec3(-1));
  b.extend(glm::dvec3(1));
  Camera c;
  c.fov_y_deg = 90;
  c.width = c.height = 100;
  c = frame_camera(b, glm::dvec3(0, 0, -1), c);
  EXPECT_NEAR(c.position.z, 2.05, 1e-12);
  EXPECT_NEAR(glm::length(glm::dvec2(c.position.x, c.position.y)), 0.0, 1e-12);
  const std::vector<PointLight> lights = frame_lights(b, c);
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_TRUE(lights[0].cast_shadows);
  EXPECT_FALSE(lights[1].cast_shadows);
  EXPECT_GT(lights[0].position.y, 1.0);  // above
  EXPECT_GT(lights[0].position.z, 1.0);  // on the camera's side
}

TEST(Framing, SceneFrameAllPlacesTheCameraAndLights) {
  SceneText s;
  s.camera = R"({"frame": "all", "width": 64, "height": 48})";
  s.lights = "[]";
  const SceneData dark = load_text(s.str());
  EXPECT_TRUE(dark.lights.empty());  // "lights": [] given: none added
  EXPECT_EQ(dark.camera.look_at, glm::dvec3(0.0));
  EXPECT_GT(dark.camera.position.z, 1.0);
  const std::string text = s.str();
  const std::string no_lights = text.substr(0, text.find(",\n\"lights\"")) + text.substr(text.find(",\n\"materials\""));
  EXPECT_EQ(load_text(no_lights).lights.size(), 2u);
  s.camera = R"({"frame": "all", "position": [0, 0, 5]})";
  EXPECT_ERROR(s.str(), "camera.position: must not be given with \"frame\"");
  s.camera = R"({"frame": "some"})";
  EXPECT_ERROR(s.str(), "camera.frame: must be \"all\"");
  s.camera = R"({"frame": "all", "direction": [0, 0, 0]})";
  EXPECT_ERROR(s.str(), "camera.direction: must be nonzero");
}

}  // namespace
}  // namespace abcube
