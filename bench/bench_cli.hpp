// The benchmark programs' command line: the option kinds they use, over CLI11, which is
// compiled once here (bench_cli.cpp) rather than in every program. Options keep the
// variables they are given as their defaults, and --help shows every default.
#pragma once
#include <memory>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace abcube {

class BenchCommandLine {
 public:
  explicit BenchCommandLine(const char* description);
  ~BenchCommandLine();
  BenchCommandLine(const BenchCommandLine&) = delete;
  BenchCommandLine& operator=(const BenchCommandLine&) = delete;

  // Required positionals: one file, or one or more.
  void file(const char* name, std::string& to, const char* help);
  void files(const char* name, std::vector<std::string>& to, const char* help);
  // A number within [lo, hi].
  void number(const char* name, int& to, const char* help, int lo, int hi);
  void number(const char* name, double& to, const char* help, double lo, double hi);
  // A number with no bound.
  void number(const char* name, unsigned& to, const char* help);
  // Comma-separated numbers, each within [lo, hi].
  void numbers(const char* name, std::vector<int>& to, const char* help, int lo, int hi);
  // One of `allowed`.
  void choice(const char* name, int& to, const char* help, const std::vector<int>& allowed);
  void choice(const char* name, std::string& to, const char* help, const std::vector<std::string>& allowed);
  // Comma-separated words, each one of `allowed`.
  void choices(const char* name, std::vector<std::string>& to, const char* help,
               const std::vector<std::string>& allowed);
  // Any text.
  void text(const char* name, std::string& to, const char* help);
  void flag(const char* name, bool& to, const char* help);

  // Parses the command line into the variables. Returns -1 to go on, or the exit status:
  // --help prints the help and gives 0; a bad command line prints "program: message" on one
  // line and gives 2 (cli.md).
  int parse(int argc, char** argv, const char* program);

 private:
  std::unique_ptr<CLI::App> app_;
};

}  // namespace abcube
