// The abcube program (cli_main.hpp): subcommands render, batch, compare, info, export-pov,
// crosscheck, report (docs/cli.md); one CLI11 parser, --help on each.
#include "cli/cli_main.hpp"

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>
#include <abcube/renderer.hpp>

#include "base/error.hpp"
#include "base/nearest_name.hpp"
#include "base/memory.hpp"
#include "base/parallel.hpp"
#include "base/temporary_file.hpp"
#include "cli/cli_common.hpp"

namespace {

// SIGINT and SIGTERM (docs/robustness.md): the first asks the work to stop at its
// next check (the render throws Interrupted, no output is put in place, the temporaries
// are removed by their owners, exit 128 + signal); a second one removes the temporary
// files at once and ends the process by the signal's default action.
volatile std::sig_atomic_t stop_signals_seen = 0;

extern "C" void on_stop_signal(int signal) {
  if (stop_signals_seen++ == 0) {
    abcube::request_stop(signal);
    return;
  }
  abcube::remove_temporary_files_now();
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  for (const int s : {SIGINT, SIGTERM}) sigaction(s, &action, nullptr);
}

// "; did you mean --width?" for the first option of the command line that `sub` does not
// know, or "".
std::string unknown_option_hint(CLI::App& sub, int argc, char** argv) {
  std::vector<std::string> known;
  for (const CLI::Option* o : sub.get_options()) {
    for (const std::string& name : o->get_lnames()) known.push_back("--" + name);
  }
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--", 0) != 0 || arg.size() < 3) continue;
    const std::string name = arg.substr(0, arg.find('='));
    if (std::find(known.begin(), known.end(), name) == known.end()) return abcube::did_you_mean(name, known);
  }
  return "";
}

}  // namespace

int abcube::cli_main(int argc, char** argv) {
  using namespace abcube;
  map_large_blocks_alone();  // freed scene-sized vectors leave the resident set at once
  CLI::App app("abcube: a headless hybrid renderer (GL raster + CPU A-buffered cube map searches)", "abcube");
  app.set_version_flag("--version", version_string());
  app.require_subcommand(1, 1);
  const CommandRun runs[] = {add_render_command(app), add_batch_command(app),      add_compare_command(app),
                             add_info_command(app),   add_export_pov_command(app), add_crosscheck_command(app),
                             add_report_command(app)};
  // Set after the commands are made, which would copy it: the citation appears once, here.
  app.footer(
      "The method: M. Eveleens and S. I. Goya, \"Calculo de Reflexiones, Refracciones y Sombras\", thesis "
      "directed by G. Rossi and G. A. Patow, Facultad de Informatica, Universidad Nacional de La Plata; the "
      "\"thesis\" modes and the error bounds named in these options are that text's (docs/methods.md cites "
      "every source). Each command's options: abcube COMMAND --help.");
  // A first word that is no option and no command is named as such (CLI11 would only say
  // that a subcommand is required).
  if (argc > 1 && argv[1][0] != '-') {
    std::string names;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands({})) {
      names += (names.empty() ? "" : ", ") + sub->get_name();
      known = known || sub->get_name() == argv[1];
    }
    if (!known) {
      std::fprintf(stderr, "abcube: unknown command %s (%s)\n", quote(argv[1]).c_str(), names.c_str());
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line naming the option, exit 2 (cli.md); the subcommand's name when there is one.
    std::string where, hint;
    for (CLI::App* sub : app.get_subcommands()) {
      where = sub->get_name() + ": ";
      hint = unknown_option_hint(*sub, argc, argv);
    }
    std::fprintf(stderr, "abcube: %s%s%s (see abcube %s--help)\n", where.c_str(), one_line(e.what(), "; ").c_str(),
                 hint.c_str(), where.empty() ? "" : (where.substr(0, where.size() - 2) + " ").c_str());
    return 2;
  }
  const CLI::App* chosen = app.get_subcommands().front();
  size_t index = 0;
  for (const CLI::App* sub : app.get_subcommands({})) {
    if (sub == chosen) break;
    ++index;
  }
  install_stop_handlers();
  try {
    const int status = runs[index]();
    // A stop asked after the last check: the work is done and whole, but the process was told to stop.
    abcube::check_stop_request();
    return status;
  } catch (const Interrupted& e) {
    std::fprintf(stderr, "abcube: %s\n", one_line(e.what(), "; ").c_str());
    return 128 + e.signal;
  } catch (const InputError& e) {
    std::fprintf(stderr, "abcube: %s\n", one_line(e.what(), "; ").c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "abcube: error: %s\n", one_line(e.what(), "; ").c_str());
    return 1;
  }
}
