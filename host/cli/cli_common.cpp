#include "cli/cli_common.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "base/error.hpp"
#include "io/image_io.hpp"
#include "render/method.hpp"

namespace abcube {

namespace {

// "--cube-res N": the help line from the table.
std::string help_line(const OptionSpec& s) {
  std::string h = s.help;
  if (s.kind == OptionKind::choice || s.kind == OptionKind::names) h += ": " + join(s.choices, " | ");
  if (s.kind == OptionKind::method) h += ": " + join(method_names(), " | ");
  std::string notes;
  if (!s.unit.empty()) notes += s.unit;
  if (!s.default_text.empty()) notes += std::string(notes.empty() ? "" : "; ") + "default: " + s.default_text;
  const std::vector<std::string> readers = methods_reading(s.key);
  if (!readers.empty()) notes += std::string(notes.empty() ? "" : "; ") + "methods: " + join(readers, ", ");
  return notes.empty() ? h : h + " (" + notes + ")";
}

const char* value_name(OptionKind k) {
  switch (k) {
    case OptionKind::integer: return "INT";
    case OptionKind::number: return "NUMBER";
    case OptionKind::path: return "PATH";
    case OptionKind::vec3: return "X,Y,Z";
    case OptionKind::names: return "NAME,...";
    case OptionKind::setting: return "KEY=VALUE";
    case OptionKind::text: return "WxH";
    default: return "NAME";
  }
}

}  // namespace

[[noreturn]] void throw_as_flag(const OptionError& e) {
  const OptionSpec* spec = find_render_option(e.key);
  throw InputError((spec ? spec->flag : e.key) + ": " + e.reason);
}

void RenderFlags::add_to(CLI::App* cmd) {
  std::vector<std::string> keys;
  for (const OptionSpec& s : render_option_table()) keys.push_back(s.key);
  add_to(cmd, keys);
}

const std::vector<std::string>& scene_view_keys() {
  static const std::vector<std::string> keys = {"width",   "height", "size", "fov_y",    "camera_position",
                                                "look_at", "up",     "set",  "max_depth"};
  return keys;
}

void RenderFlags::add_to(CLI::App* cmd, const std::vector<std::string>& keys) {
  cmd_ = cmd;
  for (const OptionSpec& s : render_option_table()) {
    if (std::find(keys.begin(), keys.end(), s.key) == keys.end()) continue;
    std::vector<std::string>& texts = texts_[s.key];
    if (s.kind == OptionKind::flag) {
      cmd->add_flag_function(
          s.flag, [&texts](int64_t) { texts.assign(1, "true"); }, help_line(s));
    } else if (s.kind == OptionKind::setting) {
      cmd->add_option(s.flag, texts, help_line(s))->type_name(value_name(s.kind))->allow_extra_args(false);
    } else {
      // names take one comma-separated value (--aovs distance,normal)
      cmd->add_option_function<std::string>(
             s.flag, [&texts](const std::string& t) { texts.assign(1, t); }, help_line(s))
          ->type_name(value_name(s.kind));
    }
  }
}

RenderSetup RenderFlags::setup() const {
  RenderSetup setup;
  try {
    for (const OptionSpec& s : render_option_table()) {
      const auto given = texts_.find(s.key);
      if (given == texts_.end()) continue;  // not a flag of this command
      for (const std::string& t : given->second) set_render_option_text(setup, s.key, t);
    }
    if (!setup.render.method.empty()) method_named(setup.render.method);  // a registered method
  } catch (const OptionError& e) {
    throw_as_flag(e);
  }
  return setup;
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
  if (access(f.c_str(), W_OK | X_OK) != 0)
    return "folder " + quote_path(f) + " is not writable (" + std::strerror(errno) + ")";
  return "";
}

}  // namespace

void check_output_path(const std::string& path, bool image) {
  if (path.empty()) return;
  if (image && !image_format_supported(path)) {
    throw InputError(path + ": no image writer for this file extension (" + join(writable_image_extensions(), ", ") +
                     ")");
  }
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::error_code ec;
  while (!dir.empty() && !std::filesystem::exists(dir, ec) && dir.has_relative_path()) dir = dir.parent_path();
  const std::string problem = folder_problem(dir);
  if (!problem.empty()) throw InputError(path + ": " + problem);
}

void make_output_folders(const std::vector<std::string>& paths) {
  for (const std::string& p : paths) {
    const std::filesystem::path dir = std::filesystem::path(p).parent_path();
    if (!p.empty() && !dir.empty()) std::filesystem::create_directories(dir);
  }
}

}  // namespace abcube
