// The render option table (<abcube/options.hpp>): each option's description, how its
// value is checked, and where it goes in RenderSetup.
#include <abcube/options.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "base/error.hpp"
#include "base/nearest_name.hpp"
#include "base/samples.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

namespace {

using nlohmann::json;

// One option: what users read (spec), how a checked value is stored (apply) and read back
// (read: null while the option keeps its default, so that "given" is read == null).
// A per-method option also says how it goes back to its default (reset), for a render by
// a method that does not read it.
struct Entry {
  OptionSpec spec;
  std::function<void(RenderSetup&, const json&)> apply;
  std::function<json(const RenderSetup&)> read;
  std::function<void(RenderOptions&)> reset;
};

std::string format_limit(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.15g", x);
  return text;
}

// A value as it appears after "got": short, one line.
std::string got(const json& v) {
  std::string text = v.dump(-1, ' ', false, json::error_handler_t::replace);
  if (text.size() > 48) text = text.substr(0, 45) + "...";
  return printable(text);
}

std::string range_text(const OptionSpec& s) { return "[" + format_limit(s.min) + ", " + format_limit(s.max) + "]"; }

[[noreturn]] void bad(const OptionSpec& s, const std::string& must, const json& v) {
  throw OptionError(s.key, "must be " + must + ", got " + got(v));
}

// Throws OptionError unless `v` is a value of `s`.
void check_value(const OptionSpec& s, const json& v) {
  switch (s.kind) {
    case OptionKind::choice:
      if (!v.is_string()) bad(s, "one of " + join(s.choices, ", "), v);
      for (const std::string& c : s.choices) {
        if (v.get<std::string>() == c) return;
      }
      throw OptionError(s.key, "must be one of " + join(s.choices, ", ") + ", got " + got(v) +
                                   did_you_mean(v.get<std::string>(), s.choices));
    case OptionKind::integer: {
      const bool whole = v.is_number_integer() ||
                         (v.is_number_float() && std::isfinite(v.get<double>()) &&
                          v.get<double>() == std::floor(v.get<double>()) && std::fabs(v.get<double>()) < 9.0e15);
      if (!whole || v.get<double>() < s.min || v.get<double>() > s.max) bad(s, "an integer in " + range_text(s), v);
      return;
    }
    case OptionKind::number:
      if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < s.min || v.get<double>() > s.max) {
        bad(s, "a number in " + range_text(s), v);
      }
      return;
    case OptionKind::flag:
      if (!v.is_boolean()) bad(s, "true or false", v);
      return;
    case OptionKind::path:
      if (!v.is_string() || v.get<std::string>().empty()) bad(s, "a path", v);
      return;
    case OptionKind::text:
      if (!v.is_string()) bad(s, "a string", v);
      return;
    case OptionKind::method:
      // Which names exist is the registry's to say: the doors check the name against it
      // (method_named) with the list of names and the nearest one.
      if (!v.is_string() || v.get<std::string>().empty()) bad(s, "a method's name", v);
      return;
    case OptionKind::vec3: {
      bool ok = v.is_array() && v.size() == 3;
      for (size_t i = 0; ok && i < 3; ++i) ok = v[i].is_number() && std::isfinite(v[i].get<double>());
      if (!ok) bad(s, "3 finite numbers", v);
      return;
    }
    case OptionKind::names: {
      if (!v.is_array()) bad(s, "a list of names (" + join(s.choices, ", ") + ")", v);
      for (const json& n : v) {
        bool known = false;
        for (const std::string& c : s.choices) known = known || (n.is_string() && n.get<std::string>() == c);
        if (!known) {
          throw OptionError(s.key, "unknown name " + got(n) + " (" + join(s.choices, ", ") + ")" +
                                       (n.is_string() ? did_you_mean(n.get<std::string>(), s.choices) : ""));
        }
      }
      return;
    }
    case OptionKind::setting:
      if (!v.is_object()) bad(s, "an object of scene values {\"camera.fov_y\": 30, ...}", v);
      for (const auto& [path, value] : v.items()) {
        if (path.empty()) bad(s, "an object whose keys are scene paths (camera.fov_y)", v);
        (void)value;
      }
      return;
  }
}

// Helpers that make the common entries.
template <class T>
json unless(const T& value, const T& fallback) {
  return value == fallback ? json() : json(value);
}

// The table reads as a table: one option an entry, its spec on a line or two, a function a
// group of options in the order --help lists them.
using Apply = std::function<void(RenderSetup&, const json&)>;
using Read = std::function<json(const RenderSetup&)>;
using Reset = std::function<void(RenderOptions&)>;
using Table = std::vector<Entry>;

void add(Table& t, OptionSpec spec, Apply apply, Read read, Reset reset = nullptr) {
  ABCUBE_CHECK(spec.per_method == static_cast<bool>(reset), "option " + spec.key + ": a per-method option has a reset");
  t.push_back({std::move(spec), std::move(apply), std::move(read), std::move(reset)});
}
// The field `member` back to RenderOptions' default.
template <class T>
Reset reset(T RenderOptions::*member) {
  return [member](RenderOptions& o) { o.*member = RenderOptions{}.*member; };
}
std::array<double, 3> vec3_of(const json& v) {
  return std::array<double, 3>{v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}
json opt_vec3(const std::optional<std::array<double, 3>>& v) { return v ? json(*v) : json(); }

// clang-format off
// What to render.
void add_what_to_render(Table& t) {
  add(t, {"method", "--method", OptionKind::method, OptionScope::job, {}, 0, 0, "the scene's render.method", "",
       false, "the rendering method", {}},
      [](RenderSetup& s, const json& v) { s.render.method = v.get<std::string>(); },
      [](const RenderSetup& s) { return unless(s.render.method, std::string()); });
  add(t, {"cube_res", "--cube-res", OptionKind::integer, OptionScope::job, {}, 1, 16384,
       "the scene's render.cube_resolution",
       "texels", true, "cube map face edge N", {}},
      [](RenderSetup& s, const json& v) { s.render.cube_resolution = v.get<int>(); },
      [](const RenderSetup& s) { return unless(s.render.cube_resolution, 0); },
      reset(&RenderOptions::cube_resolution));
  add(t, {"max_depth", "--max-depth", OptionKind::integer, OptionScope::job, {}, 0, 64, "the scene's render.max_depth",
       "bounces", false, "bounces of reflection and refraction", {}},
      [](RenderSetup& s, const json& v) { s.render.max_depth = v.get<int>(); },
      [](const RenderSetup& s) { return unless(s.render.max_depth, -1); });
  add(t, {"error_target", "--error-target", OptionKind::number, OptionScope::job, {}, 1e-12, 0.5,
       "the scene's render.error_target", "", true,
       "Error_Parallax target: the cube map's N from the bound 1/(2 N^2) of the thesis's error analysis", {}},
      [](RenderSetup& s, const json& v) { s.render.error_target = v.get<double>(); },
      [](const RenderSetup& s) { return s.render.error_target < 0 ? json() : json(s.render.error_target); },
      reset(&RenderOptions::error_target));
  add(t, {"target_db", "--target-db", OptionKind::number, OptionScope::job, {}, MIN_TARGET_DB, MAX_TARGET_DB,
       "the scene's render.target_db", "dB", true,
       "PSNR to reach against the exact tracer, from pilot renders checked against exact pixels: abuffer picks the "
       "cube map's N and shading (overrides cube_resolution), raytrace its samples a pixel (overrides samples)", {}},
      [](RenderSetup& s, const json& v) { s.render.target_db = v.get<double>(); },
      [](const RenderSetup& s) { return s.render.target_db < 0 ? json() : json(s.render.target_db); },
      reset(&RenderOptions::target_db));
  add(t, {"samples", "--samples", OptionKind::integer, OptionScope::job, {}, 1, 32, "the scene's render.samples",
       "samples a pixel", true,
       "the exact tracer's camera samples a pixel: 1 (the centre), 2, 4, 8, 16 (the first of the 32, evenly "
       "spread) or 32 (the reference)", {}},
      [](RenderSetup& s, const json& v) { s.render.samples = v.get<int>(); },
      [](const RenderSetup& s) { return unless(s.render.samples, 0); },
      reset(&RenderOptions::samples));
  add(t, {"fresnel", "--fresnel", OptionKind::flag, OptionScope::job, {}, 0, 0, "the scene's render.fresnel", "", false,
       "Schlick weights for reflect and transmit", {}},
      [](RenderSetup& s, const json& v) { s.render.fresnel = v.get<bool>(); },
      [](const RenderSetup& s) { return s.render.fresnel ? json(*s.render.fresnel) : json(); });
}

// The camera: only the values given change; the rest come from the scene.
void add_camera(Table& t) {
  add(t, {"width", "--width", OptionKind::integer, OptionScope::job, {}, 1, 32768, "the scene's camera.width",
       "pixels", false, "image width", {}},
      [](RenderSetup& s, const json& v) { s.render.camera.width = v.get<int>(); },
      [](const RenderSetup& s) { return s.render.camera.width ? json(*s.render.camera.width) : json(); });
  add(t, {"height", "--height", OptionKind::integer, OptionScope::job, {}, 1, 32768, "the scene's camera.height",
       "pixels", false, "image height", {}},
      [](RenderSetup& s, const json& v) { s.render.camera.height = v.get<int>(); },
      [](const RenderSetup& s) { return s.render.camera.height ? json(*s.render.camera.height) : json(); });
  add(t, {"size", "--size", OptionKind::text, OptionScope::job, {}, 0, 0, "the scene's camera.width x camera.height",
       "pixels", false, "image size WxH, e.g. 320x240 (width and height at once)", {}},
      [](RenderSetup& s, const json& v) {
        const std::string text = v.get<std::string>();
        int w = 0, h = 0;
        char x = 0, rest = 0;
        if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &rest) != 3 || (x != 'x' && x != 'X') || w < 1 ||
            h < 1 || w > 32768 || h > 32768) {
          throw OptionError("size", "must be WxH with each in [1, 32768], got " + got(v));
        }
        s.render.camera.width = w;
        s.render.camera.height = h;
      },
      [](const RenderSetup&) { return json(); });  // read as width and height
  add(t, {"fov_y", "--fov", OptionKind::number, OptionScope::job, {}, 1e-6, 179.999999, "the scene's camera.fov_y",
       "degrees", false, "vertical field of view", {}},
      [](RenderSetup& s, const json& v) { s.render.camera.fov_y = v.get<double>(); },
      [](const RenderSetup& s) { return s.render.camera.fov_y ? json(*s.render.camera.fov_y) : json(); });
  add(t, {"camera_position", "--camera-position", OptionKind::vec3, OptionScope::job, {}, 0, 0,
       "the scene's camera.position",
       "world units", false, "where the camera is, X,Y,Z", {}},
      [](RenderSetup& s, const json& v) { s.render.camera.position = vec3_of(v); },
      [](const RenderSetup& s) { return opt_vec3(s.render.camera.position); });
  add(t, {"look_at", "--look-at", OptionKind::vec3, OptionScope::job, {}, 0, 0, "the scene's camera.look_at",
       "world units", false, "the point the camera looks at, X,Y,Z", {}},
      [](RenderSetup& s, const json& v) { s.render.camera.look_at = vec3_of(v); },
      [](const RenderSetup& s) { return opt_vec3(s.render.camera.look_at); });
  add(t, {"up", "--up", OptionKind::vec3, OptionScope::job, {}, 0, 0, "the scene's camera.up", "", false,
       "the camera's up direction, X,Y,Z", {}},
      [](RenderSetup& s, const json& v) { s.render.camera.up = vec3_of(v); },
      [](const RenderSetup& s) { return opt_vec3(s.render.camera.up); });
  add(t, {"set", "--set", OptionKind::setting, OptionScope::job, {}, 0, 0, "none", "", false,
       "replace a value of the scene file, KEY=VALUE (VALUE as JSON, else a string): camera.fov_y=30, "
       "render.max_depth=2, lights[0].position=[1,4,2]; repeatable", {}},
      [](RenderSetup& s, const json& v) {
        for (const auto& [path, value] : v.items()) s.set.push_back({path, value.dump()});
      },
      [](const RenderSetup& s) {
        if (s.set.empty()) return json();
        json o = json::object();
        for (const SceneOverride& x : s.set) o[x.path] = json::parse(x.value, nullptr, false);
        return o;
      });
}

// Outputs and the reference.
void add_outputs(Table& t) {
  add(t, {"aovs", "--aovs", OptionKind::names, OptionScope::job, {"distance", "normal", "object_id", "shadowed",
       "fallback"}, 0, 0,
       "none", "", false, "extra outputs beside the image, comma-separated (OUT_STEM.NAME.exr)", {}},
      [](RenderSetup& s, const json& v) { s.render.aovs = v.get<std::vector<std::string>>(); },
      [](const RenderSetup& s) { return s.render.aovs.empty() ? json() : json(s.render.aovs); });
  add(t, {"reference", "--reference", OptionKind::flag, OptionScope::job, {}, 0, 0, "false", "", false,
       "also trace the exact reference; error figures in the stats", {}},
      [](RenderSetup& s, const json& v) { s.render.reference = v.get<bool>(); },
      [](const RenderSetup& s) { return unless(s.render.reference, false); });
  add(t, {"reference_image", "--reference-image", OptionKind::path, OptionScope::job, {}, 0, 0, "none", "", false,
       "the exact image rendered before (implies reference)", {}},
      [](RenderSetup& s, const json& v) { s.render.reference_image = v.get<std::string>(); },
      [](const RenderSetup& s) { return unless(s.render.reference_image, std::string()); });
  add(t, {"plan", "--plan", OptionKind::choice, OptionScope::job, {"needed", "everything"}, 0, 0, "needed", "", true,
       "everything: run and time the passes the plan skips", {}},
      [](RenderSetup& s, const json& v) { s.render.plan_everything = v.get<std::string>() == "everything"; },
      [](const RenderSetup& s) { return s.render.plan_everything ? json("everything") : json(); },
      reset(&RenderOptions::plan_everything));
}

// The map methods.
void add_map_methods(Table& t) {
  const RenderOptions d;  // the defaults
  add(t, {"search", "--search", OptionKind::choice, OptionScope::job, {"crossing", "thesis"}, 0, 0, d.search, "",
       true, "map search mode", {}},
      [](RenderSetup& s, const json& v) { s.render.search = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.search, d.search); },
      reset(&RenderOptions::search));
  add(t, {"refine", "--refine", OptionKind::choice, OptionScope::job, {"mesh", "plane"}, 0, 0, d.refine, "", true,
       "how a crossing is refined", {}},
      [](RenderSetup& s, const json& v) { s.render.refine = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.refine, d.refine); },
      reset(&RenderOptions::refine));
  add(t, {"theta_max_deg", "--theta-max", OptionKind::number, OptionScope::job, {}, 1e-6, 90,
       format_limit(d.theta_max_deg),
       "degrees", true, "the thesis search mode's acceptance angle", {}},
      [](RenderSetup& s, const json& v) { s.render.theta_max_deg = v.get<double>(); },
      [d](const RenderSetup& s) { return unless(s.render.theta_max_deg, d.theta_max_deg); },
      reset(&RenderOptions::theta_max_deg));
  add(t, {"map_only", "--map-only", OptionKind::flag, OptionScope::job, {}, 0, 0, "false", "", true,
       "searches see only the map: no side structure for the triangles it cannot hold", {}},
      [](RenderSetup& s, const json& v) { s.render.side_structure = !v.get<bool>(); },
      [](const RenderSetup& s) { return s.render.side_structure ? json() : json(true); },
      reset(&RenderOptions::side_structure));
  add(t, {"refraction", "--refraction", OptionKind::choice, OptionScope::job, {"search", "thick_lens", "thin_lens"},
       0, 0,
       d.refraction, "", true,
       "how a ray leaves a refracting object", {}},
      [](RenderSetup& s, const json& v) { s.render.refraction = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.refraction, d.refraction); },
      reset(&RenderOptions::refraction));
  add(t, {"envmap_lookup", "--envmap-lookup", OptionKind::choice, OptionScope::job, {"R", "bisector", "position"}, 0, 0,
       d.envmap_lookup, "", true,
       "the environment map's lookup direction", {}},
      [](RenderSetup& s, const json& v) { s.render.envmap_lookup = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.envmap_lookup, d.envmap_lookup); },
      reset(&RenderOptions::envmap_lookup));
  add(t, {"shading_points", "--shading-points", OptionKind::choice, OptionScope::job, {"quarters", "sparse", "one"},
       0, 0, d.shading_points, "", true,
       "shading points per camera fragment: quarters (2 to 4, more where they differ) | sparse (one, the quarters "
       "in the pixels whose colour differs from a neighbour's) | one (its centroid)",
       {}},
      [](RenderSetup& s, const json& v) { s.render.shading_points = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.shading_points, d.shading_points); },
      reset(&RenderOptions::shading_points));
  add(t, {"shadow_edges", "--shadow-edges", OptionKind::choice, OptionScope::job, {"samples", "points"}, 0, 0,
       d.shadow_edges, "", true,
       "a shadow's edge inside a camera fragment: samples (searched again from each covered sample where the "
       "shading points disagree; with the quarters) | points (the shading points' answers)",
       {}},
      [](RenderSetup& s, const json& v) { s.render.shadow_edges = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.shadow_edges, d.shadow_edges); },
      reset(&RenderOptions::shadow_edges));
  add(t, {"secondary_edges", "--secondary-edges", OptionKind::choice, OptionScope::job, {"samples", "points"}, 0, 0,
       d.secondary_edges, "", true,
       "what a mirror or glass fragment shows: samples (shaded again at each covered sample where its shading "
       "points disagree; with the quarters or sparse) | points (the shading points' answers)",
       {}},
      [](RenderSetup& s, const json& v) { s.render.secondary_edges = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.secondary_edges, d.secondary_edges); },
      reset(&RenderOptions::secondary_edges));
  add(t, {"texture_lookups", "--texture-lookups", OptionKind::choice, OptionScope::job, {"samples", "points"}, 0, 0,
       d.texture_lookups, "", true,
       "a textured fragment's base colour: samples (averaged over the covered samples each shading point stands "
       "for) | points (looked up at the shading points)",
       {}},
      [](RenderSetup& s, const json& v) { s.render.texture_lookups = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.texture_lookups, d.texture_lookups); },
      reset(&RenderOptions::texture_lookups));
  add(t, {"resolve", "--resolve", OptionKind::choice, OptionScope::job, {"exact", "thesis"}, 0, 0, d.resolve, "", true,
       "intersecting fragments: exact (per-sample priority masks) | thesis (the Vis_front estimate)", {}},
      [](RenderSetup& s, const json& v) { s.render.resolve = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.resolve, d.resolve); },
      reset(&RenderOptions::resolve));
  add(t, {"max_layers", "--max-layers", OptionKind::integer, OptionScope::job, {}, 0, 4294967295.0, "0 (all)",
       "layers", true, "A-buffer layers kept per list, 0 = all", {}},
      [](RenderSetup& s, const json& v) { s.render.max_layers = v.get<uint32_t>(); },
      [](const RenderSetup& s) { return unless(s.render.max_layers, uint32_t{0}); },
      reset(&RenderOptions::max_layers));
}

// The camera pass of the gpu and hybrid methods.
void add_gpu_camera(Table& t) {
  const RenderOptions d;  // the defaults
  add(t, {"gpu_mirrors", "--gpu-mirrors", OptionKind::choice, OptionScope::job, {"stencil", "envmap"}, 0, 0,
       d.gpu_mirrors,
       "", true, "planar mirrors by the stencil test (exact) | from the cube texture", {}},
      [](RenderSetup& s, const json& v) { s.render.gpu_mirrors = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.gpu_mirrors, d.gpu_mirrors); },
      reset(&RenderOptions::gpu_mirrors));
  add(t, {"gpu_shadows", "--gpu-shadows", OptionKind::choice, OptionScope::job, {"volumes", "maps"}, 0, 0,
       d.gpu_shadows, "", true, "shadow volumes (exact) | cube shadow maps", {}},
      [](RenderSetup& s, const json& v) { s.render.gpu_shadows = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.gpu_shadows, d.gpu_shadows); },
      reset(&RenderOptions::gpu_shadows));
  add(t, {"gpu_max_views", "--gpu-max-views", OptionKind::integer, OptionScope::job, {}, 0, 1 << 20,
       std::to_string(d.gpu_max_views), "views", true,
       "mirror views drawn per camera tile, at most (a mirror past it shows the cube texture)", {}},
      [](RenderSetup& s, const json& v) { s.render.gpu_max_views = v.get<int>(); },
      [d](const RenderSetup& s) { return unless(s.render.gpu_max_views, d.gpu_max_views); },
      reset(&RenderOptions::gpu_max_views));
  add(t, {"gpu_shading", "--gpu-shading", OptionKind::choice, OptionScope::job, {"pixels", "samples"}, 0, 0,
       d.gpu_shading,
       "", true, "shade once a pixel and surface (samples grouped) | once a sample", {}},
      [](RenderSetup& s, const json& v) { s.render.gpu_shading = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.gpu_shading, d.gpu_shading); },
      reset(&RenderOptions::gpu_shading));
  add(t, {"search_on", "--search-on", OptionKind::choice, OptionScope::job, {"auto", "gpu", "cpu"}, 0, 0, d.search_on,
       "", true,
       "gpu_abuffer and hybrid's map searches: auto (the GPU where it is hardware) | gpu (GL compute) | cpu", {}},
      [](RenderSetup& s, const json& v) { s.render.search_on = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.search_on, d.search_on); },
      reset(&RenderOptions::search_on));
  add(t, {"resolve_on", "--resolve-on", OptionKind::choice, OptionScope::job, {"auto", "gpu", "cpu"}, 0, 0,
       d.resolve_on, "", true,
       "gpu_abuffer and hybrid's resolve: auto (the GPU where it is hardware) | gpu (GL compute plans it) | cpu", {}},
      [](RenderSetup& s, const json& v) { s.render.resolve_on = v.get<std::string>(); },
      [d](const RenderSetup& s) { return unless(s.render.resolve_on, d.resolve_on); },
      reset(&RenderOptions::resolve_on));
}

// Resources and limits.
void add_resources(Table& t) {
  const RendererOptions rd;
  add(t, {"threads", "--threads", OptionKind::integer, OptionScope::job, {}, 0, 4096, "0 (every core)", "threads",
       false,
       "worker threads, for the render and for loading the scene, 0 = every core", {}},
      [](RenderSetup& s, const json& v) {
        s.render.threads = v.get<int>();
        s.renderer.threads = v.get<int>();
        s.limits.threads = v.get<int>();
      },
      [](const RenderSetup& s) { return unless(s.render.threads, 0); });
  add(t, {"timeout", "--timeout", OptionKind::number, OptionScope::job, {}, 0, 1e9, "0 (no limit)", "seconds", false,
       "stop the render past this many seconds (exit 1), 0 = no limit", {}},
      [](RenderSetup& s, const json& v) { s.render.timeout_s = v.get<double>(); },
      [](const RenderSetup& s) { return unless(s.render.timeout_s, 0.0); });
  add(t, {"max_memory", "--max-memory", OptionKind::integer, OptionScope::job, {}, 0, 1073741824.0,
       "0 (the memory available)",
       "MiB", false, "the whole render's memory budget (scene, A-buffers, maps, images)", {"max_memory_mib"}},
      [](RenderSetup& s, const json& v) {
        s.render.max_memory_mib = v.get<uint64_t>();
        s.limits.max_memory_mib = v.get<uint64_t>();  // the scene's triangles are checked as they load
      },
      [](const RenderSetup& s) { return unless(s.render.max_memory_mib, uint64_t{0}); });
  add(t, {"max_pixels", "--max-pixels", OptionKind::integer, OptionScope::job, {}, 0, 9.0e15, "0 (no cap)", "pixels",
       false,
       "refuse a larger camera image", {}},
      [](RenderSetup& s, const json& v) { s.render.max_pixels = v.get<uint64_t>(); },
      [](const RenderSetup& s) { return unless(s.render.max_pixels, uint64_t{0}); });
  add(t, {"max_triangles", "--max-triangles", OptionKind::integer, OptionScope::scene, {}, 0, 9.0e15, "0 (no cap)",
       "triangles", false, "refuse a scene with more triangles", {}},
      [](RenderSetup& s, const json& v) { s.limits.max_triangles = v.get<uint64_t>(); },
      [](const RenderSetup& s) { return unless(s.limits.max_triangles, uint64_t{0}); });
  add(t, {"root", "--root", OptionKind::path, OptionScope::scene, {}, 0, 0, "anywhere", "", false,
       "untrusted scenes: every file they reference must resolve inside this folder", {}},
      [](RenderSetup& s, const json& v) { s.limits.root = v.get<std::string>(); },
      [](const RenderSetup& s) { return unless(s.limits.root, std::string()); });
  add(t, {"gl", "--gl", OptionKind::choice, OptionScope::process,
       {"auto", "egl", "egl-device", "egl-surfaceless", "osmesa", "none"}, 0, 0, rd.gl, "", false,
       "GL path (auto: EGL device, EGL surfaceless, OSMesa, then none)", {}},
      [](RenderSetup& s, const json& v) { s.renderer.gl = v.get<std::string>(); },
      [rd](const RenderSetup& s) { return unless(s.renderer.gl, rd.gl); });
  add(t, {"gl_device", "--gl-device", OptionKind::integer, OptionScope::process, {}, 0, 1024,
       "ABCUBE_EGL_DEVICE, else the first GPU", "", false, "EGL device index", {}},
      [](RenderSetup& s, const json& v) { s.renderer.gl_device = v.get<int>(); },
      [rd](const RenderSetup& s) { return unless(s.renderer.gl_device, rd.gl_device); });
}

std::vector<Entry> make_table() {
  Table t;
  add_what_to_render(t);
  add_camera(t);
  add_outputs(t);
  add_map_methods(t);
  add_gpu_camera(t);
  add_resources(t);
  return t;
}
// clang-format on

const std::vector<Entry>& entries() {
  static const std::vector<Entry> table = make_table();
  return table;
}

const Entry* find_entry(const std::string& name) {
  for (const Entry& e : entries()) {
    if (e.spec.key == name || e.spec.flag == name) return &e;
    for (const std::string& a : e.spec.aliases) {
      if (a == name) return &e;
    }
  }
  return nullptr;
}

const Entry& need_entry(const std::string& name) {
  const Entry* e = find_entry(name);
  if (!e) throw InputError(name + ": unknown option" + did_you_mean(name, render_option_names()));
  return *e;
}

// The command line's text as the JSON value it stands for (see set_render_option_text).
json value_from_text(const OptionSpec& s, const std::string& text) {
  const auto number = [](const std::string& t, json* out) {
    const json v = json::parse(t, nullptr, false);
    if (v.is_discarded() || !v.is_number()) return false;
    *out = v;
    return true;
  };
  const auto split = [](const std::string& t) {
    std::vector<std::string> parts;
    std::stringstream in(t);
    for (std::string p; std::getline(in, p, ',');) parts.push_back(p);
    if (!t.empty() && t.back() == ',') parts.emplace_back();
    return parts;
  };
  json v;
  switch (s.kind) {
    case OptionKind::integer:
    case OptionKind::number: return number(text, &v) ? v : json(text);
    case OptionKind::flag:
      if (text == "true" || text.empty()) return true;
      if (text == "false") return false;
      return text;
    case OptionKind::vec3: {
      const std::vector<std::string> parts = split(text);
      json a = json::array();
      for (const std::string& p : parts) {
        if (!number(p, &v)) return text;
        a.push_back(v);
      }
      return a;
    }
    case OptionKind::names: return split(text);
    case OptionKind::setting: {
      const size_t eq = text.find('=');
      if (eq == std::string::npos || eq == 0) {
        throw OptionError(s.key, "must be KEY=VALUE (camera.fov_y=30), got " + quote(text));
      }
      const std::string value = text.substr(eq + 1);
      const json parsed = json::parse(value, nullptr, false);
      return json{{text.substr(0, eq), parsed.is_discarded() ? json(value) : parsed}};
    }
    case OptionKind::choice:
    case OptionKind::method:
    case OptionKind::path:
    case OptionKind::text: return text;
  }
  return text;
}

void apply(RenderSetup& setup, const Entry& e, const json& v) {
  check_value(e.spec, v);
  e.apply(setup, v);
}

}  // namespace

const std::vector<OptionSpec>& render_option_table() {
  static const std::vector<OptionSpec> specs = [] {
    std::vector<OptionSpec> s;
    for (const Entry& e : entries()) s.push_back(e.spec);
    return s;
  }();
  return specs;
}

const OptionSpec* find_render_option(const std::string& name) {
  const Entry* e = find_entry(name);
  return e ? &e->spec : nullptr;
}

std::vector<std::string> render_option_names() {
  std::vector<std::string> names;
  for (const Entry& e : entries()) {
    names.push_back(e.spec.key);
    names.push_back(e.spec.flag);
  }
  return names;
}

void set_render_option(RenderSetup& setup, const std::string& name, const std::string& json_value) {
  const Entry& e = need_entry(name);
  const json v = json::parse(json_value, nullptr, false);
  if (v.is_discarded()) throw OptionError(e.spec.key, "not a JSON value, got " + quote(json_value));
  apply(setup, e, v);
}

void set_render_option_text(RenderSetup& setup, const std::string& name, const std::string& text) {
  const Entry& e = need_entry(name);
  apply(setup, e, value_from_text(e.spec, text));
}

void check_render_options(const RenderOptions& options) {
  RenderSetup setup;
  setup.render = options;
  for (const Entry& e : entries()) {
    if (e.spec.scope != OptionScope::job || e.spec.key == "size") continue;
    const json v = e.read(setup);
    if (!v.is_null()) check_value(e.spec, v);
  }
  if (options.samples != 0 && !is_sample_rung(options.samples)) {
    throw OptionError("samples", "must be 1, 2, 4, 8, 16 or 32, got " + std::to_string(options.samples));
  }
  // Options that contradict one another.
  if (options.target_db > 0 && options.samples != 0) {
    throw OptionError("target_db", "chooses the tracer's samples, and so does samples (--samples): give one");
  }
  if (options.target_db > 0 && (options.cube_resolution != 0 || options.error_target >= 0)) {
    const OptionSpec& other = *find_render_option(options.cube_resolution != 0 ? "cube_res" : "error_target");
    throw OptionError("target_db",
                      "chooses the cube map's N, and so does " + other.key + " (" + other.flag + "): give one");
  }
}

std::vector<std::string> given_render_options(const RenderOptions& options) {
  RenderSetup setup;
  setup.render = options;
  std::vector<std::string> keys;
  for (const Entry& e : entries()) {
    if (e.spec.scope == OptionScope::job && !e.read(setup).is_null()) keys.push_back(e.spec.key);
  }
  return keys;
}

void reset_render_option(RenderOptions& options, const std::string& key) {
  const Entry& e = need_entry(key);
  ABCUBE_CHECK(e.reset != nullptr, "option " + key + " is read by every method: it has no reset");
  e.reset(options);
}

}  // namespace abcube
