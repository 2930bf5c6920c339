// abcube report SCENE -o DIR: the comparison page (<abcube/report.hpp>).
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>

#include <abcube/report.hpp>
#include <nlohmann/json.hpp>

#include "base/error.hpp"
#include "cli/cli_common.hpp"

namespace abcube {

namespace {

struct ReportCommand {
  std::string scene, dir, methods = "abuffer,gpu,hybrid,zbuffer,envmap", sweep;
  bool no_crosscheck = false;
  RenderFlags flags;

  static std::vector<std::string> split(const std::string& text) {
    std::vector<std::string> parts;
    std::stringstream in(text);
    for (std::string p; std::getline(in, p, ',');) {
      if (!p.empty()) parts.push_back(p);
    }
    return parts;
  }

  int run() const {
    if (dir.empty()) throw InputError("-o DIR: an output folder is required");
    check_output_path((std::filesystem::path(dir) / "index.html").string(), false);
    ReportOptions o;
    o.methods = split(methods);
    for (const std::string& n : split(sweep)) {
      size_t used = 0;
      int value = 0;
      try {
        value = std::stoi(n, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != n.size()) throw InputError("--sweep: must be cube resolutions N,N,..., got " + quote(n));
      o.sweep.push_back(value);
    }
    RenderSetup setup = flags.setup();
    o.render = setup.render;
    o.renderer = setup.renderer;
    o.crosscheck = !no_crosscheck;
    if (stderr_is_terminal()) o.progress = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
    const Scene s = Scene::load(scene, setup.limits, setup.set);
    ReportResult r;
    try {
      r = write_report(s, dir, o);
    } catch (const OptionError& e) {
      throw_as_flag(e);
    }
    const nlohmann::json j = nlohmann::json::parse(r.json);
    std::printf("report %s: %s\n", scene.c_str(), r.index_html.c_str());
    for (const std::string& m : o.methods) {
      const nlohmann::json& x = j["methods"][m];
      if (x.contains("failed")) {
        std::printf("  %-9s not rendered: %s\n", m.c_str(), x["failed"].get<std::string>().c_str());
        continue;
      }
      const nlohmann::json& db = x["error"]["psnr_db"];
      const nlohmann::json& rung = x["matched_rung"];
      std::printf(
          "  %-9s %s dB in %.0f ms; the tracer at %d samples a pixel is as close in %.0f ms (time ratio %.2f)\n",
          m.c_str(), db.is_number() ? std::to_string(db.get<double>()).c_str() : "inf", x["total_ms"].get<double>(),
          rung["samples"].get<int>(), rung["total_ms"].get<double>(), rung["time_ratio"].get<double>());
    }
    if (j["crosscheck"].contains("pass")) {
      std::printf("  crosscheck %s\n", j["crosscheck"]["pass"].get<bool>() ? "PASS" : "FAIL");
    }
    print_warnings(s, "abcube: ");
    return 0;
  }
};

}  // namespace

CommandRun add_report_command(CLI::App& app) {
  auto c = std::make_shared<ReportCommand>();
  CLI::App* cmd = app.add_subcommand(
      "report",
      "the comparison page: the scene rendered by each method and by the exact tracer, side by side, heat maps, error "
      "per method, per surface and object, time against error with the tracer at 1 to 32 samples a pixel and the "
      "fastest way to each method's error, time per pass and the GPU against the CPU, in DIR/index.html "
      "(self-contained, offline)");
  cmd->add_option("SCENE", c->scene, "scene file, or a model file (.gltf, .glb, .obj)")->required()->type_name("PATH");
  cmd->add_option("-o,--output", c->dir, "output folder: index.html, report.json, images/, stats/ (made if missing)")
      ->type_name("PATH");
  cmd->add_option("--methods", c->methods,
                  "the methods compared with raytrace, comma-separated (default: abuffer,gpu,hybrid,zbuffer,envmap)")
      ->type_name("NAME,...");
  cmd->add_option("--sweep", c->sweep,
                  "abuffer again at these cube resolutions, comma-separated (e.g. 64,128,256,512), for the developers' "
                  "section")
      ->type_name("N,...");
  cmd->add_flag("--no-crosscheck", c->no_crosscheck, "leave out the GPU-against-CPU crosscheck");
  c->flags.add_to(cmd);
  return [c] { return c->run(); };
}

}  // namespace abcube
