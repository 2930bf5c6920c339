// The jobs file of `abcube batch`: its lines read and checked (batch_jobs.hpp).
#include "cli/batch_jobs.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <cstdint>
#include <filesystem>
#include <utility>

#include <nlohmann/json.hpp>

#include "base/error.hpp"
#include "base/nearest_name.hpp"
#include "base/input_file.hpp"
#include "io/image_io.hpp"

namespace abcube {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The next line of `in` without its line break, or false at the end of the file. Reads at
// most MAX_JOB_LINE_BYTES + 1 bytes of it, so that the caller can refuse it.
bool read_line(std::istream& in, std::string& text) {
  text.clear();
  for (int c = in.get(); c != std::char_traits<char>::eof(); c = in.get()) {
    if (c == '\n' || text.size() > MAX_JOB_LINE_BYTES) return true;
    text.push_back(static_cast<char>(c));
  }
  return !text.empty();
}

// Reads one job from its JSON line; InputError "FILE:LINE: reason" for anything malformed.
class JobReader {
 public:
  JobReader(std::string file) : file_(std::move(file)), dir_(fs::path(file_).parent_path()) {}

  Job read(const std::string& text, size_t line) const {
    Job job;
    job.line = line;
    json j;
    try {
      j = json::parse(text);
    } catch (const json::exception& e) {  // a syntax error, or a number past a double's range (out_of_range)
      fail(line, "not JSON: " + printable(e.what(), 240));
    }
    if (!j.is_object()) fail(line, "a job must be a JSON object");
    for (const auto& [key, value] : j.items()) read_key(job, key, value);
    try {  // each value was checked alone; now the ones that contradict one another
      check_render_options(job.setup(RenderSetup{}).render);
    } catch (const OptionError& e) {
      fail(line, quote(e.key) + ": " + e.reason);
    }
    if (job.scene.empty()) fail(line, "\"scene\": required");
    if (job.out.empty()) fail(line, "\"out\": required");
    if (!image_format_supported(job.out)) fail(line, "\"out\": no image writer for " + quote_path(job.out));
    return job;
  }

  [[noreturn]] void fail(size_t line, const std::string& why) const {
    throw InputError(file_ + ":" + std::to_string(line) + ": " + why);
  }

 private:
  std::string path(const json& v, size_t line, const char* key) const {
    if (!v.is_string() || v.get<std::string>().empty()) fail(line, std::string("\"") + key + "\": must be a path");
    const fs::path p(v.get<std::string>());
    return (p.is_absolute() ? p : dir_ / p).lexically_normal().string();
  }

  // The table's option `key` (for "camera" members: the key they stand for) with value
  // `v`, checked on a scratch setup so that a bad value is refused before anything renders,
  // with the table's message under the name the line used.
  void add_option(Job& job, const std::string& key, const std::string& shown, const json& v) const {
    const std::string text = v.dump();
    RenderSetup scratch;
    try {
      set_render_option(scratch, key, text);
    } catch (const OptionError& e) {
      fail(job.line, quote(shown) + ": " + e.reason);
    }
    job.options.emplace_back(key, text);
  }

  void read_camera(Job& job, const json& c) const {
    if (!c.is_object()) fail(job.line, "\"camera\": must be an object");
    static const std::vector<std::string> known = {"position", "look_at", "up", "fov_y", "width", "height"};
    for (const auto& [key, v] : c.items()) {
      const std::string where = "camera." + key;
      if (std::find(known.begin(), known.end(), key) == known.end()) {
        fail(job.line, quote(where) + ": unknown key (" + join(known, ", ") + ")" + did_you_mean(key, known));
      }
      add_option(job, key == "position" ? "camera_position" : key, where, v);
    }
  }

  void read_key(Job& job, const std::string& key, const json& v) const {
    if (key == "scene")
      job.scene = path(v, job.line, "scene");
    else if (key == "out")
      job.out = path(v, job.line, "out");
    else if (key == "stats")
      job.stats = path(v, job.line, "stats");
    else if (key == "camera")
      read_camera(job, v);
    else if (key == "reference_image" && v.is_string() && !v.get<std::string>().empty()) {
      add_option(job, key, key, json(path(v, job.line, "reference_image")));  // relative to the jobs file
    } else {
      const OptionSpec* spec = find_render_option(key);
      if (!spec || spec->key != key) {  // flags ("--cube-res") and aliases are the command line's and Python's
        std::vector<std::string> known = {"scene", "out", "stats", "camera"};
        for (const OptionSpec& s : render_option_table()) {
          if (s.scope == OptionScope::job) known.push_back(s.key);
        }
        fail(job.line, quote(key) + ": unknown key" + did_you_mean(key, known) +
                           " (scene, out, stats, camera and the render options of `abcube render --help` by their "
                           "snake_case names)");
      }
      if (spec->scope != OptionScope::job) {
        fail(job.line, quote(key) + ": set for the whole batch on its command line (" + spec->flag + "), not per job");
      }
      add_option(job, key, key, v);
    }
  }

  std::string file_;
  fs::path dir_;
};

}  // namespace

RenderSetup Job::setup(const RenderSetup& base) const {
  RenderSetup s = base;
  for (const auto& [key, value] : options) set_render_option(s, key, value);
  return s;
}

std::vector<Job> read_jobs(std::istream& in, const std::string& jobs_path, size_t shard_i, size_t shard_n) {
  const JobReader reader(jobs_path);
  std::vector<Job> mine;
  std::string text;
  size_t line = 0, index = 0;
  while (read_line(in, text)) {
    ++line;
    if (text.size() > MAX_JOB_LINE_BYTES) {
      reader.fail(line, "longer than " + format_bytes(MAX_JOB_LINE_BYTES) + " (a job is one short JSON object)");
    }
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;  // blank lines hold no job
    Job job = reader.read(text, line);
    if (index++ % shard_n == shard_i) mine.push_back(std::move(job));
  }
  if (in.bad()) throw InputError(jobs_path + ": read error");
  return mine;
}

}  // namespace abcube
