#include "cli/cli_common.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "base/error.hpp"
#include "io/image_io.hpp"

namespace abcube {

Args::Args(const std::vector<std::string>& words, const std::vector<std::string>& with_value,
           const std::vector<std::string>& flags) {
  auto contains = [](const std::vector<std::string>& v, const std::string& s) {
    return std::find(v.begin(), v.end(), s) != v.end();
  };
  for (size_t i = 0; i < words.size(); ++i) {
    std::string w = words[i];
    if (w.size() > 1 && w[0] == '-' && !(w.size() > 1 && (std::isdigit(static_cast<unsigned char>(w[1])) || w[1] == '.'))) {
      std::string value;
      bool inline_value = false;
      const size_t eq = w.find('=');
      if (eq != std::string::npos && w.rfind("--", 0) == 0) {
        value = w.substr(eq + 1);
        w = w.substr(0, eq);
        inline_value = true;
      }
      if (contains(flags, w) && !inline_value) {
        values_[w] = "1";
      } else if (contains(with_value, w)) {
        if (!inline_value) {
          if (i + 1 >= words.size()) throw InputError(w + ": needs a value");
          value = words[++i];
        }
        values_[w] = value;
      } else {
        throw InputError(w + ": unknown option");
      }
    } else {
      positional_.push_back(w);
    }
  }
}

std::string Args::get(const std::string& name, const std::string& fallback) const {
  auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

int Args::get_int(const std::string& name, int fallback, int lo, int hi) const {
  if (!has(name)) return fallback;
  const std::string s = get(name);
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || errno != 0 || v < lo || v > hi) {
    throw InputError(name + ": must be an integer in [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "], got '" + s + "'");
  }
  return static_cast<int>(v);
}

double Args::get_double(const std::string& name, double fallback, double lo, double hi) const {
  if (!has(name)) return fallback;
  const std::string s = get(name);
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(v) || v < lo || v > hi) {
    throw InputError(name + ": must be a number in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                     "], got '" + s + "'");
  }
  return v;
}

void Args::expect_positional(size_t count, const std::string& what) const {
  if (positional_.size() < count) throw InputError("missing " + what);
  if (positional_.size() > count) throw InputError("unexpected argument '" + positional_[count] + "'");
}

bool stderr_is_terminal() { return isatty(STDERR_FILENO) == 1; }

std::function<void(const std::string&, double)> progress_printer() {
  if (!stderr_is_terminal()) return nullptr;
  return [](const std::string& stage, double done) {
    std::fprintf(stderr, "\r%s %3d%%%s", stage.c_str(), int(done * 100), done >= 1 ? "\n" : "");
  };
}

RenderOptions render_options_from(const Args& args) {
  RenderOptions o;
  o.method = args.get("--method");
  o.cube_resolution = args.get_int("--cube-res", 0, 1, 16384);
  o.max_depth = args.get_int("--max-depth", -1, 0, 64);
  o.error_target = args.get_double("--error-target", -1, 0.0, 0.5);
  if (args.has("--fresnel")) o.fresnel = true;
  o.reference_image = args.get("--reference-image");
  o.reference = args.has("--reference");
  const std::string plan = args.get("--plan", "needed");
  if (plan != "needed" && plan != "everything") {
    throw InputError("--plan: must be needed or everything, got '" + plan + "'");
  }
  o.plan_everything = plan == "everything";
  o.search = args.get("--search", o.search);
  o.refine = args.get("--refine", o.refine);
  o.theta_max_deg = args.get_double("--theta-max", o.theta_max_deg, 1e-6, 90.0);
  o.refraction = args.get("--refraction", o.refraction);
  o.envmap_lookup = args.get("--envmap-lookup", o.envmap_lookup);
  o.max_layers = static_cast<uint32_t>(args.get_int("--max-layers", 0, 0, 1 << 20));
  o.max_memory_mib = static_cast<uint64_t>(args.get_int("--max-memory", 0, 0, 1 << 30));
  o.max_pixels = static_cast<uint64_t>(args.get_double("--max-pixels", 0, 0, 1e15));
  o.timeout_s = args.get_double("--timeout", 0, 0, 1e9);
  const std::string aovs = args.get("--aovs");
  for (size_t start = 0; start < aovs.size();) {
    const size_t comma = std::min(aovs.find(',', start), aovs.size());
    if (comma > start) o.aovs.push_back(aovs.substr(start, comma - start));
    start = comma + 1;
  }
  return o;
}

std::string aov_path(const std::string& output, const std::string& aov) {
  const std::filesystem::path p(output);
  return (p.parent_path() / (p.stem().string() + "." + aov + ".exr")).string();
}

void write_outputs(const std::string& output, const RenderResult& result) {
  write_image(output, result.image);
  for (const auto& [name, image] : result.aovs) write_image(aov_path(output, name), image);
}

}  // namespace abcube
