// Small pieces the abcube subcommands share: argument parsing, timing, progress.
#pragma once
#include <chrono>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <abcube/renderer.hpp>

#include "base/timer.hpp"

namespace abcube {

// Command-line words after the subcommand. Options are "--name value" or "--flag";
// everything else is positional. Every error is an InputError naming the option.
class Args {
 public:
  // `with_value` lists options that take a value, `flags` those that do not.
  Args(const std::vector<std::string>& words, const std::vector<std::string>& with_value,
       const std::vector<std::string>& flags);

  bool has(const std::string& name) const { return values_.count(name) > 0; }
  std::string get(const std::string& name, const std::string& fallback = "") const;
  // Integer option in [lo, hi]; `fallback` when absent.
  int get_int(const std::string& name, int fallback, int lo, int hi) const;
  double get_double(const std::string& name, double fallback, double lo, double hi) const;
  const std::vector<std::string>& positional() const { return positional_; }
  // Requires exactly `count` positional arguments named by `what` (for the message).
  void expect_positional(size_t count, const std::string& what) const;

 private:
  std::map<std::string, std::string> values_;
  std::vector<std::string> positional_;
};



// True when stderr is a terminal (progress is shown only then).
bool stderr_is_terminal();

// "stage NN%" on stderr when it is a terminal; null (quiet) otherwise (cli.md).
std::function<void(const std::string&, double)> progress_printer();

// The render options the command line gives (render's options; batch's shared ones).
RenderOptions render_options_from(const Args& args);

// The image, and each AOV beside it as OUT_STEM.NAME.exr (float), each written atomically.
void write_outputs(const std::string& output, const RenderResult& result);
std::string aov_path(const std::string& output, const std::string& aov);

int cmd_render(const std::vector<std::string>& words);
int cmd_info(const std::vector<std::string>& words);
int cmd_compare(const std::vector<std::string>& words);
int cmd_export_pov(const std::vector<std::string>& words);
int cmd_crosscheck(const std::vector<std::string>& words);

}  // namespace abcube
