// What the abcube subcommands share: their registration on one CLI11 parser (main.cpp),
// the render options render and batch both take, output writing and progress.
#pragma once
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <abcube/options.hpp>
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
CommandRun add_report_command(CLI::App& app);

// The render options of the table (<abcube/options.hpp>) as command-line flags of a
// subcommand: their help, defaults and units from the table; their values checked by it.
struct RenderFlags {
  // Registers every option of the table on `cmd`, or only those of `keys`.
  void add_to(CLI::App* cmd);
  void add_to(CLI::App* cmd, const std::vector<std::string>& keys);
  // The options given, applied in the table's order (a repeated --set keeps each); an
  // InputError naming the flag for a bad value.
  RenderSetup setup() const;

 private:
  CLI::App* cmd_ = nullptr;
  std::map<std::string, std::vector<std::string>> texts_;  // table key -> each value given
};

// The table's keys of the scene as seen: its camera (size, field of view, placement), its
// values replaced (--set), its bounces; for the commands that take a scene but render no
// method (crosscheck, export-pov).
const std::vector<std::string>& scene_view_keys();

// An option the table refuses, named by its flag ("--cube-res: must be ...").
[[noreturn]] void throw_as_flag(const OptionError& e);

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

// Refuses before any work an output whose format has no writer (naming those there are)
// or whose folder cannot be made or written (InputError naming the output and the
// folder). Render and batch share the rule: missing folders are made, once the work is done
// (make_output_folders), so that a failed run leaves nothing behind.
void check_output_path(const std::string& path, bool image);
// The folders of these outputs ("" skipped), made where missing.
void make_output_folders(const std::vector<std::string>& paths);

}  // namespace abcube
