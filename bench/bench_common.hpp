// Shared by the benchmark programs: errors become one line and the cli.md exit codes.
#pragma once
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

#include "base/error.hpp"

namespace abcube {

// The comma-separated items of a list option ("256,512,1024").
inline std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');) out.push_back(item);
  return out;
}

// An integer option value; bad text is an InputError naming the option (exit 2).
inline int parse_int(const std::string& option, const std::string& text) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno != 0 || v < 0 || v > 1000000000L) {
    throw InputError(option + ": not a non-negative integer: '" + text + "'");
  }
  return static_cast<int>(v);
}

inline std::vector<int> parse_int_list(const std::string& option, const std::string& text) {
  std::vector<int> out;
  for (const std::string& item : split_list(text)) out.push_back(parse_int(option, item));
  if (out.empty()) throw InputError(option + ": empty list");
  return out;
}

// The words of a command line, one option at a time: next() moves to the next word,
// word() is it, value() takes the word after it as its argument (InputError when missing).
class ArgWalk {
 public:
  ArgWalk(int argc, char** argv) : argc_(argc), argv_(argv) {}
  bool next() { return ++i_ < argc_; }
  std::string word() const { return argv_[i_]; }
  std::string value() {
    if (i_ + 1 >= argc_) throw InputError(word() + ": needs a value");
    return argv_[++i_];
  }

 private:
  int argc_;
  char** argv_;
  int i_ = 0;
};

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

}  // namespace abcube
