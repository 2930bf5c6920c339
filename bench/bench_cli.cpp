#include "bench_cli.hpp"

#include <algorithm>
#include <cstdio>

#include <CLI/CLI.hpp>

namespace abcube {

BenchCommandLine::BenchCommandLine(const char* description) : app_(std::make_unique<CLI::App>(description)) {
  app_->option_defaults()->always_capture_default();
}

BenchCommandLine::~BenchCommandLine() = default;

void BenchCommandLine::file(const char* name, std::string& to, const char* help) {
  app_->add_option(name, to, help)->required();
}

void BenchCommandLine::files(const char* name, std::vector<std::string>& to, const char* help) {
  app_->add_option(name, to, help)->required();
}

void BenchCommandLine::number(const char* name, int& to, const char* help, int lo, int hi) {
  app_->add_option(name, to, help)->check(CLI::Range(lo, hi));
}

void BenchCommandLine::number(const char* name, double& to, const char* help, double lo, double hi) {
  app_->add_option(name, to, help)->check(CLI::Range(lo, hi));
}

void BenchCommandLine::number(const char* name, unsigned& to, const char* help) { app_->add_option(name, to, help); }

void BenchCommandLine::numbers(const char* name, std::vector<int>& to, const char* help, int lo, int hi) {
  app_->add_option(name, to, help)->delimiter(',')->allow_extra_args(false)->check(CLI::Range(lo, hi));
}

void BenchCommandLine::choice(const char* name, int& to, const char* help, const std::vector<int>& allowed) {
  app_->add_option(name, to, help)->check(CLI::IsMember(allowed));
}

void BenchCommandLine::choice(const char* name, std::string& to, const char* help,
                              const std::vector<std::string>& allowed) {
  app_->add_option(name, to, help)->check(CLI::IsMember(allowed));
}

void BenchCommandLine::choices(const char* name, std::vector<std::string>& to, const char* help,
                               const std::vector<std::string>& allowed) {
  app_->add_option(name, to, help)->delimiter(',')->allow_extra_args(false)->check(CLI::IsMember(allowed));
}

void BenchCommandLine::text(const char* name, std::string& to, const char* help) { app_->add_option(name, to, help); }

void BenchCommandLine::flag(const char* name, bool& to, const char* help) { app_->add_flag(name, to, help); }

int BenchCommandLine::parse(int argc, char** argv, const char* program) {
  try {
    app_->parse(argc, argv);
    return -1;
  } catch (const CLI::CallForHelp&) {
    std::fputs(app_->help().c_str(), stdout);
    return 0;
  } catch (const CLI::ParseError& e) {
    std::string message = e.what();
    std::replace(message.begin(), message.end(), '\n', ' ');
    std::fprintf(stderr, "%s: %s\n", program, message.c_str());
    return 2;
  }
}

}  // namespace abcube
