// Shared by the benchmark programs: the command line (CLI11) and errors as one line with
// the cli.md exit codes.
#pragma once
#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>

#include <abcube/error.hpp>

namespace abcube {

// A CLI11 app whose --help shows every option's default.
inline void show_defaults(CLI::App& app) { app.option_defaults()->always_capture_default(); }

// Parses the command line into `app`'s variables. Returns -1 to go on, or the exit status:
// --help prints the help and gives 0; a bad command line prints "name: message" on one
// line and gives 2 (cli.md).
inline int parse_command_line(CLI::App& app, int argc, char** argv, const char* name) {
  try {
    app.parse(argc, argv);
    return -1;
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    return 0;
  } catch (const CLI::ParseError& e) {
    std::string message = e.what();
    std::replace(message.begin(), message.end(), '\n', ' ');
    std::fprintf(stderr, "%s: %s\n", name, message.c_str());
    return 2;
  }
}

// Runs fn(); bad input -> "name: message", exit 2; any other failure -> exit 1.
template <class Fn>
int guarded_main(const char* name, Fn&& fn) {
  try {
    return fn();
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s: %s\n", name, e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", name, e.what());
    return 1;
  }
}

// A benchmark program's whole main: its options registered by add_options(app, options)
// on a parser described by `description`, parsed (parse_command_line), then
// run(options) under guarded_main.
template <class Options, class AddOptions, class Run>
int bench_main(int argc, char** argv, const char* name, const char* description, AddOptions&& add_options, Run&& run) {
  Options options;
  CLI::App app{description};
  add_options(app, options);
  if (const int status = parse_command_line(app, argc, argv, name); status >= 0) return status;
  return guarded_main(name, [&] { return run(options); });
}

}  // namespace abcube
