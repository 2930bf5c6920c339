// What the abcube subcommands share: their registration on one CLI11 parser (main.cpp),
// the render options render and batch both take, output writing and progress.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <abcube/renderer.hpp>

namespace abcube {

// A subcommand's action, run after the whole command line parsed: returns the exit status.
using CommandRun = std::function<int()>;

// Each adds its subcommand (options, defaults, units, help) to `app` and returns its action.
CommandRun add_render_command(CLI::App& app);
CommandRun add_batch_command(CLI::App& app);
CommandRun add_compare_command(CLI::App& app);
CommandRun add_info_command(CLI::App& app);
CommandRun add_export_pov_command(CLI::App& app);
CommandRun add_crosscheck_command(CLI::App& app);

// The options of one render that render and batch share (renderer.hpp RenderOptions,
// RendererOptions, SceneLimits), registered on a subcommand with their defaults and units.
struct RenderFlags {
  RenderOptions options;
  RendererOptions renderer;
  SceneLimits limits;
  std::string plan = "needed";
  std::vector<std::string> aovs;
  // `per_render`: the options a batch job can also set per line (method, sizes, ...).
  void add_to(CLI::App* cmd);
  // The options as parsed (validates --plan); InputError naming the option.
  RenderOptions render_options() const;
};

// True when stderr is a terminal (progress is shown only then).
bool stderr_is_terminal();

// "stage NN%" on stderr when it is a terminal; null (quiet) otherwise (cli.md).
std::function<void(const std::string&, double)> progress_printer();

// The image, and each AOV beside it as OUT_STEM.NAME.exr (float), each written atomically.
void write_outputs(const std::string& output, const RenderResult& result);
std::string aov_path(const std::string& output, const std::string& aov);

// The scene's warnings (Scene::warnings) on stderr, one line each after `prefix`. Called
// once the work succeeded, so that a failure stays one line (cli.md).
void print_warnings(const Scene& scene, const std::string& prefix);

// Refuses before any work an output whose format has no writer or whose folder is missing
// or not writable (InputError naming the output and the folder).
void check_output_path(const std::string& path, bool image);
// For an output whose missing folders will be made (batch): why that cannot work (the
// nearest existing folder on its path is no folder, or not writable), or "".
std::string creatable_output_problem(const std::string& path);

}  // namespace abcube
