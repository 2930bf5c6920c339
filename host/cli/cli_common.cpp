#include "cli/cli_common.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "base/error.hpp"
#include "io/image_io.hpp"

namespace abcube {

void RenderFlags::add_to(CLI::App* cmd) {
  cmd->add_option("--method", options.method,
                  "abuffer | zbuffer | envmap | raytrace | gpu | hybrid (default: the scene's render.method)");
  cmd->add_option("--cube-res", options.cube_resolution,
                  "cube map face edge N, texels (default: the scene's render.cube_resolution)")
      ->check(CLI::Range(1, 16384));
  cmd->add_option("--max-depth", options.max_depth, "bounces of reflection and refraction (default: the scene's)")
      ->check(CLI::Range(0, 64));
  cmd->add_option("--threads", renderer.threads, "worker threads, 0 = every core")
      ->capture_default_str()->check(CLI::Range(0, 4096));
  cmd->add_option("--gl", renderer.gl, "GL path: auto | egl | egl-device | egl-surfaceless | osmesa | none")
      ->capture_default_str();
  cmd->add_option("--gl-device", renderer.gl_device, "EGL device index (default: ABCUBE_EGL_DEVICE, else the first GPU)")
      ->check(CLI::Range(0, 1024));
  cmd->add_flag("--reference", options.reference,
                "also trace the exact reference; error figures in the stats");
  cmd->add_option("--reference-image", options.reference_image,
                  "the exact image rendered before (implies --reference)");
  cmd->add_option("--error-target", options.error_target,
                  "Error_Parallax target: N from the bound 1/(2 N^2) (thesis 9.3.4), in (0, 0.5]")
      ->check(CLI::Range(0.0, 0.5));
  cmd->add_option("--plan", plan, "needed | everything (run and time what the plan skips)")->capture_default_str();
  cmd->add_option("--search", options.search, "map search mode: crossing | thesis (thesis 7.4)")->capture_default_str();
  cmd->add_option("--refine", options.refine, "crossing refinement: mesh | plane")->capture_default_str();
  cmd->add_option("--theta-max", options.theta_max_deg, "thesis mode's acceptance angle, degrees")
      ->capture_default_str()->check(CLI::Range(1e-6, 90.0));
  cmd->add_option("--refraction", options.refraction, "search | thick_lens | thin_lens")->capture_default_str();
  cmd->add_option("--envmap-lookup", options.envmap_lookup, "envmap method's lookup: R | bisector | position")
      ->capture_default_str();
  cmd->add_option("--resolve", options.resolve,
                  "intersecting fragments: exact (per-sample priority masks, thesis 11.2.4) | thesis (Vis_front, 5.2.1.2)")
      ->capture_default_str();
  cmd->add_flag("--map-only", [this](int64_t) { options.side_structure = false; },
                "searches see only the map: no side structure for triangles it cannot hold");
  cmd->add_option("--gpu-mirrors", options.gpu_mirrors,
                  "gpu: planar mirrors by the stencil test (exact) | envmap (the cube texture, as before)")
      ->capture_default_str();
  cmd->add_option("--gpu-shadows", options.gpu_shadows, "gpu: shadow volumes (exact) | maps (cube shadow maps)")
      ->capture_default_str();
  cmd->add_option("--gpu-max-views", options.gpu_max_views,
                  "gpu: mirror views drawn per camera tile, at most (a mirror past it shows the cube texture)")
      ->capture_default_str()->check(CLI::Range(0, 1 << 20));
  cmd->add_option("--gpu-shading", options.gpu_shading,
                  "gpu: shade once a pixel and surface, its samples grouped by triangle and shadow | once a sample")
      ->capture_default_str();
  cmd->add_flag("--fresnel", [this](int64_t) { options.fresnel = true; }, "Schlick weights for kr and kt");
  cmd->add_option("--max-layers", options.max_layers, "A-buffer layers kept per list, 0 = all")
      ->capture_default_str()->check(CLI::Range(0, 1 << 20));
  cmd->add_option_function<uint64_t>(
         "--max-memory",
         [this](uint64_t mib) {
           options.max_memory_mib = mib;
           limits.max_memory_mib = mib;  // the scene's triangles are checked as they load
         },
         "the whole render's memory budget (scene, A-buffers, maps, images), MiB, 0 = the memory available")
      ->default_str("0")->check(CLI::Range(uint64_t{0}, uint64_t{1} << 30));
  cmd->add_option("--max-pixels", options.max_pixels, "refuse a larger camera image, pixels, 0 = no cap")
      ->capture_default_str();
  cmd->add_option("--max-triangles", limits.max_triangles, "refuse a scene with more triangles, 0 = no cap")
      ->capture_default_str();
  cmd->add_option("--root", limits.root, "untrusted scenes: every file they reference must resolve inside DIR");
  cmd->add_option("--aovs", aovs, "extra outputs beside the image, comma-separated: distance, normal, object_id, fallback (OUT_STEM.NAME.exr)")
      ->delimiter(',');
}

RenderOptions RenderFlags::render_options() const {
  if (plan != "needed" && plan != "everything") {
    throw InputError("--plan: must be needed or everything, got " + quote(plan));
  }
  RenderOptions o = options;
  o.plan_everything = plan == "everything";
  o.aovs = aovs;
  return o;
}

bool stderr_is_terminal() { return isatty(STDERR_FILENO) == 1; }

std::function<void(const std::string&, double)> progress_printer() {
  if (!stderr_is_terminal()) return nullptr;
  return [](const std::string& stage, double done) {
    std::fprintf(stderr, "\r%s %3d%%%s", stage.c_str(), int(done * 100), done >= 1 ? "\n" : "");
  };
}

std::string aov_path(const std::string& output, const std::string& aov) {
  const std::filesystem::path p(output);
  return (p.parent_path() / (p.stem().string() + "." + aov + ".exr")).string();
}

void write_outputs(const std::string& output, const RenderResult& result) {
  write_image(output, result.image);
  for (const auto& [name, image] : result.aovs) write_image(aov_path(output, name), image);
}

void print_warnings(const Scene& scene, const std::string& prefix) {
  for (const std::string& w : scene.warnings()) std::fprintf(stderr, "%s%s\n", prefix.c_str(), one_line(w).c_str());
}

namespace {

// Why files cannot be made in `folder` (the temporary of an atomic write goes beside the
// output), or "".
std::string folder_problem(const std::filesystem::path& folder) {
  const std::string f = folder.empty() ? "." : folder.string();
  if (!std::filesystem::is_directory(folder.empty() ? "." : folder)) return "folder " + quote_path(f) + " is no folder";
  if (access(f.c_str(), W_OK | X_OK) != 0) return "folder " + quote_path(f) + " is not writable (" + std::strerror(errno) + ")";
  return "";
}

}  // namespace

void check_output_path(const std::string& path, bool image) {
  if (path.empty()) return;
  if (image && !image_format_supported(path)) throw InputError(path + ": no image writer for this file extension");
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (!dir.empty() && !std::filesystem::exists(dir)) {
    throw InputError(path + ": folder " + quote_path(dir.string()) + " does not exist");
  }
  const std::string problem = folder_problem(dir);
  if (!problem.empty()) throw InputError(path + ": " + problem);
}

std::string creatable_output_problem(const std::string& path) {
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::error_code ec;
  while (!dir.empty() && !std::filesystem::exists(dir, ec) && dir.has_relative_path()) dir = dir.parent_path();
  return folder_problem(dir);
}

}  // namespace abcube
