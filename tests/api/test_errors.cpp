// Errors through the public API: each is the exception its kind promises (error.hpp),
// with a message naming the place, never an exit or an abort.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <abcube/renderer.hpp>

#include "api_test_support.hpp"
#include "base/error.hpp"
#include "tiny_scene.hpp"

namespace abcube::test {
namespace {

// The message of the InputError `fn` throws ("" when it throws none).
template <class Fn>
std::string input_error_of(Fn&& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ErrorsApi, BadSceneValueNamesItsFieldPath) {
  std::string json = tiny_scene_json(8, 8, 16);
  const std::string radius = "\"radius\": 0.5";
  ASSERT_NE(json.find(radius), std::string::npos);
  json.replace(json.find(radius), radius.size(), "\"radius\": -1");
  const std::string message = input_error_of([&] { Scene::from_json(json, "bad.json"); });
  EXPECT_NE(message.find("objects[2].radius"), std::string::npos) << message;
  EXPECT_NE(message.find("bad.json"), std::string::npos) << message;
}

// 100,000 nested arrays (200 KB) used to overflow the stack (SIGSEGV); now an InputError
// that names the line and column where the nesting goes too deep.
TEST(ErrorsApi, DeeplyNestedSceneIsAnInputError) {
  const std::string text = std::string(100000, '[') + std::string(100000, ']');
  const std::string message = input_error_of([&] { Scene::from_json(text, "deep.json"); });
  EXPECT_EQ(message.rfind("deep.json:1:65: ", 0), 0u) << message.substr(0, 200);
  EXPECT_NE(message.find("nested deeper than 64 levels"), std::string::npos) << message.substr(0, 200);
}

// An empty mesh is no error: Scene::warnings names it, and the scene renders.
TEST(ErrorsApi, EmptyMeshIsAWarning) {
  const std::string dir = std::string(ABCUBE_BINARY_DIR) + "/test_api_empty_mesh";
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/empty.obj").close();
  std::string json = tiny_scene_json(8, 8, 16);
  const std::string objects = "\"objects\": [";
  ASSERT_NE(json.find(objects), std::string::npos);
  json.insert(json.find(objects) + objects.size(), R"({"type": "mesh", "file": "empty.obj"}, )");
  const Scene scene = Scene::from_json(json, "s.json", dir);
  ASSERT_EQ(scene.warnings().size(), 1u);
  EXPECT_EQ(scene.warnings()[0], "s.json: objects[0].file: warning: mesh \"empty.obj\" has no triangles");
  EXPECT_TRUE(Scene::from_json(tiny_scene_json(8, 8, 16)).warnings().empty());
  Renderer renderer(RendererOptions{"none", -1, 1});
  EXPECT_EQ(renderer.render(scene, small_options("raytrace", 8, 8, 16)).image.width, 8);
}

TEST(ErrorsApi, CameraOverrideFovOutOfRange) {
  const Scene scene = Scene::from_json(tiny_scene_json(8, 8, 16));
  Renderer renderer(RendererOptions{"none", -1, 1});
  RenderOptions o;
  o.camera.fov_y = 200;
  const std::string message = input_error_of([&] { renderer.render(scene, o); });
  EXPECT_NE(message.find("fov_y"), std::string::npos) << message;
}

TEST(ErrorsApi, UnknownMethod) {
  const Scene scene = Scene::from_json(tiny_scene_json(8, 8, 16));
  Renderer renderer(RendererOptions{"none", -1, 1});
  RenderOptions o;
  o.method = "photon";
  const std::string message = input_error_of([&] { renderer.render(scene, o); });
  EXPECT_NE(message.find("photon"), std::string::npos) << message;
}

// A render far longer than its limit stops with RenderTimeout (the cornell box at its own
// 512x512 size, exact tracer at 32 samples per pixel: seconds of work against 1 ns).
TEST(ErrorsApi, TimeoutStopsALongRender) {
  const Scene scene = Scene::load(scene_path("cornell.json"));
  Renderer renderer(RendererOptions{"none", -1, 0});
  RenderOptions o;
  o.method = "raytrace";
  o.timeout_s = 1e-9;
  EXPECT_THROW(renderer.render(scene, o), RenderTimeout);
  // The Renderer is still usable after a timeout.
  const RenderResult r = renderer.render(scene, small_options("raytrace", 8, 8, 16));
  EXPECT_EQ(r.image.width, 8);
}

// A gpu render stopped by its limit (at the first check: inside the shadow maps) leaves the
// Renderer's GL scene as good as new: the next render equals a new Renderer's, byte for byte.
TEST(ErrorsApi, GpuTimeoutLeavesTheGlSceneWhole) {
  const Scene scene = Scene::from_json(tiny_scene_json(32, 24, 32));
  Renderer renderer;
  RenderOptions o;
  o.method = "gpu";
  o.timeout_s = 1e-9;
  try {
    renderer.render(scene, o);
    FAIL() << "no timeout";
  } catch (const RenderTimeout&) {
  } catch (const RuntimeFailure& e) {
    GTEST_SKIP() << "no GL here: " << e.what();
  }
  o.timeout_s = 0;
  const RenderResult after = renderer.render(scene, o);
  Renderer fresh;
  EXPECT_TRUE(images_equal(after.image, fresh.render(scene, o).image));
}

// THE RADIANCE BOUND (scene/radiance.hpp): a scene whose pixels could pass a float's range is
// refused with one line naming the value to lower; one just under the bound, with a mirror
// and glass doubling what each bounce can return, renders finite pixels with every method,
// none above the bound. A deeper --max-depth is checked again.
TEST(ErrorsApi, RadianceOverAFloatIsRefusedAndTheBoundRendersFinite) {
  const auto scene_with = [](const std::string& ambient) {
    return R"({"version": 1, "camera": {"position": [0, 1, 3], "look_at": [0, 0.5, 0], "width": 16, "height": 12},
      "ambient": [)" +
           ambient + ", " + ambient + ", " + ambient + R"(],
      "lights": [{"type": "point", "position": [1, 3, 2], "color": [1, 1, 1]}],
      "materials": {"both": {"color": [1, 1, 1], "reflect": 1, "transmit": 1, "ior": 1.5}, "white": {}},
      "objects": [{"type": "quad", "vertices": [[-3, 0, -3], [3, 0, -3], [3, 0, 3], [-3, 0, 3]], "material": "white"},
                  {"type": "sphere", "center": [0, 0.6, 0], "radius": 0.5, "segments": 12, "material": "both"}],
      "render": {"max_depth": 4}})";
  };
  const std::string message = input_error_of([&] { Scene::from_json(scene_with("3.4e38"), "over.json"); });
  EXPECT_EQ(
      message.rfind("over.json: ambient: with this scene's lights, colours and max_depth 4, a pixel could reach ", 0),
      0u)
      << message;
  EXPECT_NE(message.find("got 3.4e+38"), std::string::npos) << message;
  // At the bound: (ambient + 2 lights) (1 + 2 + 4 + 8 + 16) <= 1e37.
  const Scene scene = Scene::from_json(scene_with("3.2e35"), "edge.json");
  Renderer renderer;
  for (const char* method : {"raytrace", "abuffer", "zbuffer", "envmap", "gpu", "hybrid"}) {
    RenderOptions o;
    o.method = method;
    if (std::string(method) != "raytrace") o.cube_resolution = 16;
    const Image image = renderer.render(scene, o).image;
    float top = 0;
    for (const float v : image.data) {
      ASSERT_TRUE(std::isfinite(v)) << method;
      top = std::max(top, v);
    }
    EXPECT_GT(top, 1e35f) << method;
    EXPECT_LE(top, 1e37f) << method;
  }
  RenderOptions deeper;
  deeper.max_depth = 8;
  const std::string depth = input_error_of([&] { renderer.render(scene, deeper); });
  EXPECT_EQ(depth.rfind("edge.json: ambient: with this scene's lights, colours and max_depth 8", 0), 0u) << depth;
}

TEST(ErrorsApi, GpuWithoutGlIsInputError) {
  const Scene scene = Scene::from_json(tiny_scene_json(8, 8, 16));
  Renderer renderer(RendererOptions{"none", -1, 1});
  RenderOptions o;
  o.method = "gpu";
  const std::string message = input_error_of([&] { renderer.render(scene, o); });
  EXPECT_NE(message.find("gpu"), std::string::npos) << message;
}

// A failed internal check throws InternalError naming the check (a host program survives it).
TEST(ErrorsApi, InternalCheckThrowsInsteadOfAborting) {
  const int operand = 3;
  try {
    ABCUBE_CHECK(operand == 4, "operand is " + std::to_string(operand));
    FAIL() << "ABCUBE_CHECK(false) returned";
  } catch (const InternalError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("operand == 4"), std::string::npos) << message;
    EXPECT_NE(message.find("operand is 3"), std::string::npos) << message;
  }
}

// ---- Input text in messages (base/error.hpp): quoted, escaped, cut ----------------------

// No byte a terminal would act on: C0 controls, DEL, and the C1 controls (raw or UTF-8).
bool terminal_safe(const std::string& s) {
  for (size_t i = 0; i < s.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c < 0x20 || c == 0x7F) return false;
    if (c >= 0x80 && c <= 0x9F && (i == 0 || static_cast<unsigned char>(s[i - 1]) != 0xC2)) continue;  // continuation
    if (c == 0xC2 && i + 1 < s.size() && static_cast<unsigned char>(s[i + 1]) <= 0x9F) return false;
  }
  return true;
}

TEST(ErrorsQuote, EscapesControlBytesAndQuotes) {
  EXPECT_EQ(quote("glass"), "\"glass\"");
  EXPECT_EQ(quote("my \"glass\" \\ 2"), "\"my \\\"glass\\\" \\\\ 2\"");
  // OSC title and SGR colour sequences, as an OBJ usemtl could hold them.
  EXPECT_EQ(quote("\x1b]0;pwned\x07\x1b[31mred"), "\"\\e]0;pwned\\x07\\e[31mred\"");
  EXPECT_EQ(quote(std::string("a\nb\rc\td\0e\x7f", 10)), "\"a\\nb\\rc\\td\\x00e\\x7F\"");
  // UTF-8 passes; the C1 control U+009B (CSI) and bytes that are not UTF-8 are escaped.
  EXPECT_EQ(quote("verre \xC3\xA9 \xE2\x82\xAC"), "\"verre \xC3\xA9 \xE2\x82\xAC\"");
  EXPECT_EQ(quote("\xC2\x9B"
                  "31m"),
            "\"\\xC2\\x9B31m\"");
  EXPECT_EQ(quote("\x9B"
                  "31m \xFF \xC3"),
            "\"\\x9B31m \\xFF \\xC3\"");
  EXPECT_EQ(quote("\xED\xA0\x80"), "\"\\xED\\xA0\\x80\"");  // a surrogate
  EXPECT_EQ(printable("a\x1b[2Jb\"\\"), "a\\e[2Jb\"\\");    // unquoted: " and \ stay
}

TEST(ErrorsQuote, LongTextIsCutWithItsLength) {
  const std::string name(200000, 'm');
  const std::string q = quote(name);
  EXPECT_EQ(q, "\"" + std::string(QUOTE_MAX_CHARS, 'm') + "\"... (200000 bytes)");
  EXPECT_EQ(printable(name, 10), "mmmmmmmmmm... (200000 bytes)");
  EXPECT_EQ(quote(std::string(QUOTE_MAX_CHARS, 'm')), "\"" + std::string(QUOTE_MAX_CHARS, 'm') + "\"");  // not cut
  // Characters are counted, not bytes: a cut never splits one.
  std::string accents;
  for (int i = 0; i < 100; ++i) accents += "\xC3\xA9";
  std::string expected;
  for (size_t i = 0; i < QUOTE_MAX_CHARS; ++i) expected += "\xC3\xA9";
  EXPECT_EQ(quote(accents), "\"" + expected + "\"... (200 bytes)");
}

// A path is cut by the bytes it shows, escapes included: a name of 1,100 control bytes
// (fuzz_obj's mtllib, once 4,247 bytes of message) shows 256 escapes of 4 bytes, no more.
TEST(ErrorsQuote, PathIsCutByTheBytesItShows) {
  const std::string plain(QUOTE_PATH_MAX_BYTES, 'p');
  EXPECT_EQ(quote_path(plain), "\"" + plain + "\"");  // not cut
  const std::string controls(1100, '\x01');
  std::string expected;
  for (size_t i = 0; i < QUOTE_PATH_MAX_BYTES / 4; ++i) expected += "\\x01";
  EXPECT_EQ(quote_path(controls), "\"" + expected + "\"... (1100 bytes)");
  // A cut never splits an escape: 1,023 bytes of room take 255 escapes.
  EXPECT_EQ(quote(controls, SIZE_MAX, 1023), "\"" + expected.substr(4) + "\"... (1100 bytes)");
}

TEST(ErrorsQuote, OneLineJoinsLinesAndEscapesTheRest) {
  EXPECT_EQ(one_line("a\nb\r\nc\td  \n"), "a b c d");
  EXPECT_EQ(one_line("shader log:\nline 1\nline 2\n", "; "), "shader log:; line 1; line 2");
  EXPECT_EQ(one_line("x \x1b]0;t\x07 y"), "x \\e]0;t\\x07 y");
  EXPECT_TRUE(terminal_safe(one_line(std::string("\x01\x02\x1b\x7f\xC2\x9B\x9B", 7))));
}

// A scene with hostile names: every message is one short line a terminal can print as is.
TEST(ErrorsQuote, SceneMessagesAreShortAndTerminalSafe) {
  const std::string long_key(5 << 20, 'k');
  std::string json = tiny_scene_json(8, 8, 16);
  // As written in the JSON text: ESC ] 0 ; ... BEL, ESC [ 31 m, and the C1 CSI U+009B.
  const std::vector<std::string> hostile = {long_key, "\\u001b]0;pwned\\u0007\\u001b[31mred", "\\u009b2J"};
  for (const std::string& key : hostile) {
    const std::string text = "{\"" + key + "\": 1, " + json.substr(json.find('{') + 1);
    const std::string message = input_error_of([&] { Scene::from_json(text, "bad.json"); });
    EXPECT_NE(message.find("bad.json: "), std::string::npos) << message;
    EXPECT_NE(message.find("unknown field"), std::string::npos) << message;
    EXPECT_LT(message.size(), 400u) << message.substr(0, 400);
    EXPECT_TRUE(terminal_safe(message)) << message;
  }
}

}  // namespace
}  // namespace abcube::test
