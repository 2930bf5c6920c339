// The comparison report (<abcube/report.hpp>): the renders, the figures of each method
// against the exact tracer, the sweep, the crosscheck and the context, gathered into
// report.json; report_html.cpp draws the page from it.
#include <abcube/report.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <thread>

#include <abcube/options.hpp>
#include <nlohmann/json.hpp>

#include "base/error.hpp"
#include "base/timer.hpp"
#include "gl/gl_context.hpp"
#include "io/image_io.hpp"
#include "io/metrics.hpp"
#include "render/crosscheck.hpp"
#include "render/render_methods.hpp"
#include "render/report_html.hpp"
#include "render/stats_json.hpp"
#include "scene/plan.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// What kind of surface an object is, by its material: the error is reported per kind.
std::string surface_kind(const Material& m) {
  if (m.transmit > 0) return "glass";
  if (m.reflect > 0) return "mirror";
  if (m.opacity < 1) return "translucent";
  return "diffuse";
}

// The error of `image` against `reference` per object and per kind of surface, over the
// pixels whose centre sees that object in the reference (`object_id`, -1 for none); and
// over the pixels whose centre surface is in some light's shadow (`shadowed` > 0), whatever
// its kind ("in shadow": those pixels are in their kind's figures too).
json error_by_region(const Image& image, const Image& reference, const Image& object_id, const Image& shadowed,
                     const SceneData& scene) {
  struct Sum {
    double sq = 0;
    size_t pixels = 0, over_2 = 0;
  };
  std::map<int, Sum> by_object;
  std::map<std::string, Sum> by_kind;
  const auto displayed = [](const Image& i, int x, int y) {
    const glm::vec3 c = i.rgb(x, y);
    return glm::dvec3(srgb_encode(c.r), srgb_encode(c.g), srgb_encode(c.b));
  };
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const int id = static_cast<int>(object_id.at(x, y)[0]);
      const glm::dvec3 d = glm::abs(displayed(image, x, y) - displayed(reference, x, y));
      const double m = std::max(d.x, std::max(d.y, d.z));
      const std::string kind = id < 0 || static_cast<size_t>(id) >= scene.objects.size()
                                   ? "background"
                                   : surface_kind(scene.materials[scene.objects[static_cast<size_t>(id)].material]);
      const auto add = [&](Sum* s) {
        s->sq += glm::dot(d, d);
        ++s->pixels;
        s->over_2 += m > 2.0 / 255.0 + 1e-6;
      };
      add(&by_object[id]);
      add(&by_kind[kind]);
      if (shadowed.at(x, y)[0] > 0) add(&by_kind["in shadow"]);
    }
  }
  const auto figures = [](const Sum& s) {
    const double rmse = std::sqrt(s.sq / (3.0 * static_cast<double>(s.pixels)));
    return json{{"pixels", s.pixels},
                {"rmse", rmse},
                {"psnr_db", rmse > 0 ? json(20 * std::log10(1 / rmse)) : json("inf")},
                {"share_over_2_255", static_cast<double>(s.over_2) / static_cast<double>(s.pixels)}};
  };
  json objects = json::array();
  for (const auto& [id, s] : by_object) {
    json o = figures(s);
    o["object"] = id;
    if (id >= 0 && static_cast<size_t>(id) < scene.objects.size()) {
      const SceneObject& so = scene.objects[static_cast<size_t>(id)];
      o["name"] = so.path + " (" + so.type + ")";
      o["material"] = scene.materials[so.material].name;
      o["kind"] = surface_kind(scene.materials[so.material]);
    } else {
      o["name"] = "background";
      o["kind"] = "background";
    }
    objects.push_back(o);
  }
  json kinds = json::object();
  for (const auto& [kind, s] : by_kind) kinds[kind] = figures(s);
  return {{"objects", objects}, {"kinds", kinds}};
}

// A value of /proc/cpuinfo or /proc/meminfo ("model name", "MemTotal"), or "".
std::string proc_value(const char* file, const std::string& key) {
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(key, 0) != 0) continue;
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    const size_t start = line.find_first_not_of(" \t", colon + 1);
    return start == std::string::npos ? "" : line.substr(start);
  }
  return "";
}

// A render's timings under names without dots (report.json's keys are paths, dots between
// keys): "raytrace.trace" -> "raytrace trace".
json timings(const std::map<std::string, double>& t) {
  json out = json::object();
  for (const auto& [name, ms] : t) {
    std::string key = name;
    std::replace(key.begin(), key.end(), '.', ' ');
    out[key] = ms;
  }
  return out;
}

class Report {
 public:
  Report(const Scene& scene, const std::string& dir, const ReportOptions& options)
      : scene_(scene), dir_(dir), o_(options) {}

  ReportResult run() {
    const Clock::time_point start = Clock::now();
    check_methods();
    fs::create_directories(fs::path(dir_) / "images");
    fs::create_directories(fs::path(dir_) / "stats");
    j_["scene"] = scene_.name();
    j_["method_order"] = o_.methods;  // the page's order (JSON objects keep none)
    {
      Renderer renderer(o_.renderer);
      render_reference(renderer);
      render_ladder(renderer);
      for (const std::string& m : o_.methods) render_method(renderer, m);
      match_rungs();
      render_sweep(renderer);
      j_["context"]["gl_path"] = renderer.gl_path();
      j_["context"]["gl_renderer"] = renderer.gl_renderer();
    }  // the Renderer's GL context closed before the crosscheck opens its own
    run_crosscheck();
    context();
    j_["report_ms"] = ms_since(start) - render_ms_;
    j_["render_ms"] = render_ms_;
    ReportResult r;
    r.json = j_.dump(2);
    r.methods_failed = failed_;
    write_text_atomic((fs::path(dir_) / "report.json").string(), r.json + "\n");
    r.index_html = (fs::path(dir_) / "index.html").string();
    write_text_atomic(r.index_html, report_html(j_));
    return r;
  }

 private:
  void say(const std::string& line) const {
    if (o_.progress) o_.progress(line);
  }

  void check_methods() const {
    std::set<std::string> seen;
    for (const std::string& m : o_.methods) {
      const std::vector<std::string>& known = method_names();
      if (std::find(known.begin(), known.end(), m) == known.end()) {
        throw InputError("methods: unknown method " + quote(m) + " (" + join(known, ", ") + ")" +
                         did_you_mean(m, known));
      }
      if (m == "raytrace") throw InputError("methods: raytrace is the reference, always rendered");
      if (!seen.insert(m).second) throw InputError("methods: " + m + " given twice");
    }
    for (int n : o_.sweep) {
      if (n < 1 || n > 16384) throw InputError("sweep: each N must be in [1, 16384], got " + std::to_string(n));
    }
    // Render options the report decides itself, refused rather than left unused.
    const RenderOptions& r = o_.render;
    if (!r.method.empty()) throw OptionError("method", "not used by report: it renders each method of methods");
    if (!r.aovs.empty()) throw OptionError("aovs", "not used by report: it writes the images it shows, no AOVs");
    if (r.reference || !r.reference_image.empty()) {
      throw OptionError(r.reference_image.empty() ? "reference" : "reference_image",
                        "not used by report: it traces its own reference, the exact image at 32 samples a pixel");
    }
    if (r.samples != 0) {
      throw OptionError("samples", "not used by report: it traces the exact image at every rung of samples itself");
    }
  }

  std::string path(const std::string& relative) const { return (fs::path(dir_) / relative).string(); }

  // One render, timed; its stats kept in stats/NAME.json.
  RenderResult render(Renderer& renderer, RenderOptions options, const std::string& name) {
    options.stats = true;
    const Clock::time_point t0 = Clock::now();
    RenderResult r = renderer.render(scene_, options);
    render_ms_ += ms_since(t0);
    write_text_atomic(path("stats/" + name + ".json"), r.stats.json + "\n");
    return r;
  }

  void render_reference(Renderer& renderer) {
    say("rendering the reference (raytrace)");
    RenderOptions options = without_unused_options(o_.render, "raytrace");
    options.samples = 0;  // the reference: 32 samples a pixel
    options.target_db = -1;
    options.aovs = {"object_id", "shadowed"};
    options.reference = false;
    options.reference_image.clear();
    RenderResult r = render(renderer, options, "raytrace");
    reference_ = std::move(r.image);
    object_id_ = std::move(r.aovs.at("object_id"));
    shadowed_ = std::move(r.aovs.at("shadowed"));
    write_image(path("images/raytrace.exr"), reference_);
    write_image(path("images/raytrace.png"), reference_);
    j_["size"] = {{"width", reference_.width}, {"height", reference_.height}};
    j_["reference"] = {{"method", "raytrace"},
                       {"image", "images/raytrace.png"},
                       {"stats", "stats/raytrace.json"},
                       {"total_ms", r.stats.total_ms},
                       {"timings_ms", timings(r.stats.timings_ms)}};
  }

  // The exact tracer's rivals: the same tracer at 1, 2, 4, 8 and 16 samples a pixel (THE
  // SAMPLE LADDER), each timed and measured against the reference; with the reference's own
  // time (its AOVs' pass left out) as the rung of 32. The chart's curve and the figures each
  // method's time is held to.
  void render_ladder(Renderer& renderer) {
    json rungs = json::array();
    for (int s : {1, 2, 4, 8, 16}) {
      say("rendering raytrace at " + std::to_string(s) + (s == 1 ? " sample" : " samples") + " a pixel");
      RenderOptions options = without_unused_options(o_.render, "raytrace");
      options.samples = s;
      options.target_db = -1;
      options.aovs.clear();
      options.reference = false;
      options.reference_image.clear();
      const RenderResult r = render(renderer, options, "raytrace_" + std::to_string(s));
      rungs.push_back({{"samples", s},
                       {"total_ms", r.stats.total_ms},
                       {"error", image_error_json(image_error(r.image, reference_))},
                       {"stats", "stats/raytrace_" + std::to_string(s) + ".json"}});
    }
    const json& t = j_["reference"]["timings_ms"];
    rungs.push_back({{"samples", 32},
                     {"total_ms", j_["reference"]["total_ms"].get<double>() - t.value("aovs", 0.0)},
                     {"error", {{"psnr_db", "inf"}}},
                     {"stats", "stats/raytrace.json"}});
    j_["ladder"] = rungs;
  }

  // Each method's matched rung: the fastest rung of the ladder at least as close to the
  // reference as the method, its time and the ratio to it (above 1: the tracer at that many
  // samples was faster at this error); and the Pareto front of every point, methods and
  // rungs: those no other point beats in time and error both.
  void match_rungs() {
    const auto psnr = [](const json& error) {
      const json& v = error["psnr_db"];
      return v.is_number() ? v.get<double>() : std::numeric_limits<double>::infinity();
    };
    for (const std::string& m : o_.methods) {
      json& x = j_["methods"][m];
      if (x.contains("failed")) continue;
      const double db = psnr(x["error"]);
      const json* best = nullptr;
      for (const json& rung : j_["ladder"]) {
        if (psnr(rung["error"]) >= db && (!best || rung["total_ms"].get<double>() < (*best)["total_ms"].get<double>()))
          best = &rung;
      }
      const double ms = (*best)["total_ms"].get<double>();
      x["matched_rung"] = {
          {"samples", (*best)["samples"]}, {"total_ms", ms}, {"time_ratio", x["total_ms"].get<double>() / ms}};
    }
    struct Point {
      std::string name;
      double ms, db;
    };
    std::vector<Point> points;
    for (const json& rung : j_["ladder"]) {
      points.push_back({"raytrace " + rung["samples"].dump(), rung["total_ms"].get<double>(), psnr(rung["error"])});
    }
    for (const std::string& m : o_.methods) {
      const json& x = j_["methods"][m];
      if (!x.contains("failed")) points.push_back({m, x["total_ms"].get<double>(), psnr(x["error"])});
    }
    json front = json::array();
    for (const Point& p : points) {
      bool beaten = false;
      for (const Point& q : points) {
        beaten = beaten || (q.ms <= p.ms && q.db >= p.db && (q.ms < p.ms || q.db > p.db));
      }
      if (!beaten) front.push_back(p.name);
    }
    j_["front"] = front;
  }

  void render_method(Renderer& renderer, const std::string& method) {
    say("rendering " + method);
    json& m = j_["methods"][method];
    RenderOptions options = without_unused_options(o_.render, method);
    options.reference_image = path("images/raytrace.exr");
    options.aovs.clear();
    RenderResult r;
    try {
      r = render(renderer, options, method);
    } catch (const std::exception& e) {  // no GL for gpu, a memory cap, ...: on the page with why
      m["failed"] = one_line(e.what());
      ++failed_;
      return;
    }
    write_image(path("images/" + method + ".png"), r.image);
    write_image(path("images/" + method + ".heat.png"), with_heatmap_legend(error_heatmap(r.image, reference_)));
    const ImageError e = image_error(r.image, reference_);
    const json stats = json::parse(r.stats.json);
    m["image"] = "images/" + method + ".png";
    m["heat"] = "images/" + method + ".heat.png";
    m["stats"] = "stats/" + method + ".json";
    m["error"] = image_error_json(e);
    m["total_ms"] = r.stats.total_ms;
    m["timings_ms"] = timings(r.stats.timings_ms);
    m["regions"] = error_by_region(r.image, reference_, object_id_, shadowed_, scene_.data());
    if (stats.contains("plan")) m["plan"] = stats["plan"];
    if (stats.contains("reference") && stats["reference"].contains("ray_error")) {
      m["ray_error"] = stats["reference"]["ray_error"];
    }
  }

  void render_sweep(Renderer& renderer) {
    json points = json::array();
    for (int n : o_.sweep) {
      say("sweep: abuffer at N = " + std::to_string(n));
      RenderOptions options = without_unused_options(o_.render, "abuffer");
      options.cube_resolution = n;
      options.error_target = -1;
      options.reference_image = path("images/raytrace.exr");
      options.aovs.clear();
      const RenderResult r = render(renderer, options, "sweep_" + std::to_string(n));
      const json stats = json::parse(r.stats.json);
      json p = {{"n", n},
                {"total_ms", r.stats.total_ms},
                {"error", image_error_json(image_error(r.image, reference_))},
                {"bound_1_over_2n2", parallax_bound(n)}};
      const json& ray = stats["reference"]["ray_error"];
      if (ray.is_object()) {
        p["error_parallax_mean"] = ray["error_parallax"]["mean"];
        p["error_parallax_max"] = ray["error_parallax"]["max"];
        p["error_parallax_within_bound"] = ray["error_parallax_within_bound"];
      }
      points.push_back(p);
    }
    j_["sweep"] = {{"method", "abuffer"}, {"points", points}};
  }

  void run_crosscheck() {
    json& c = j_["crosscheck"];
    c["covers"] =
        "visibility (the cube map's nearest layer texel by texel, which object each camera sample sees), "
        "direct shading of interior pixels, hard shadows sample by sample against the exact tracer";
    c["does_not_cover"] =
        "reflections, refractions and antialiased edges, where the methods differ by design: the "
        "sections above compare every method with the exact tracer there";
    if (!o_.crosscheck) {
      c["skipped"] = "not asked for";
      return;
    }
    GlChoice choice = GlChoice::automatic;
    if (!parse_gl_choice(o_.renderer.gl, &choice) || choice == GlChoice::none) {
      c["skipped"] = "no GL (--gl " + o_.renderer.gl + "): the crosscheck compares GL with the CPU";
      return;
    }
    say("crosscheck: GPU against CPU");
    std::string log;
    const std::unique_ptr<GlContext> ctx = open_gl_context(choice, o_.renderer.gl_device, &log);
    if (!ctx) {
      c["skipped"] = "no GL path works here: " + one_line(log);
      return;
    }
    // The renders' camera and cube resolution (size, camera and --set overrides applied).
    SceneData data = scene_view(scene_.data(), without_unused_options(o_.render, "abuffer"));
    const CrosscheckTolerances tol;
    const Clock::time_point t0 = Clock::now();
    const CrosscheckResult r = crosscheck(data, data.render.cube_resolution, o_.render.threads, tol);
    c["ms"] = ms_since(t0);
    c["gl"] = describe_gl(ctx.get());
    c["result"] = crosscheck_json(r, tol);
    c["pass"] = r.pass;
    c["failures"] = r.failures;
    write_image(path("images/crosscheck_samples.png"), disagreement_overlay(r.sample_disagreement, r.cpu_image));
    c["samples_image"] = "images/crosscheck_samples.png";
    size_t differing = 0;
    for (float s : r.sample_disagreement.data) differing += s > 0;
    c["pixels_with_differing_samples"] = differing;
    if (r.shadow_lights > 0) {
      write_image(path("images/crosscheck_shadows.png"), disagreement_overlay(r.shadow_disagreement, Image()));
      c["shadows_image"] = "images/crosscheck_shadows.png";
    }
  }

  void context() {
    json& c = j_["context"];
    c["version"] = version_string();
    c["cpu"] = proc_value("/proc/cpuinfo", "model name");
    c["cores"] = std::thread::hardware_concurrency();
    c["memory"] = proc_value("/proc/meminfo", "MemTotal");
    char host[256] = {};
    c["host"] = gethostname(host, sizeof host - 1) == 0 ? std::string(host) : std::string();
    const SceneData& s = scene_.data();
    c["scene"] = {
        {"triangles", s.triangles->triangle_count()},
        {"objects", s.objects.size()},
        {"lights", s.lights.size()},
        {"materials", s.materials.size()},
        {"cube_resolution", o_.render.cube_resolution > 0 ? o_.render.cube_resolution : s.render.cube_resolution},
        {"max_depth", o_.render.max_depth >= 0 ? o_.render.max_depth : s.render.max_depth}};
  }

  const Scene& scene_;
  std::string dir_;
  const ReportOptions& o_;
  json j_;
  Image reference_, object_id_, shadowed_;
  double render_ms_ = 0;
  int failed_ = 0;
};

}  // namespace

ReportResult write_report(const Scene& scene, const std::string& dir, const ReportOptions& options) {
  return Report(scene, dir, options).run();
}

}  // namespace abcube
