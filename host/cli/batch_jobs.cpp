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

  int integer(const json& v, size_t line, const std::string& key) const {
    const bool fits = v.is_number_unsigned() ? v.get<uint64_t>() <= uint64_t{INT_MAX}
                      : v.is_number_integer() && v.get<int64_t>() >= INT_MIN && v.get<int64_t>() <= INT_MAX;
    if (!fits) fail(line, "\"" + key + "\": must be an integer (32 bits)");
    return v.get<int>();
  }

  std::array<double, 3> vec3(const json& v, size_t line, const std::string& key) const {
    if (!v.is_array() || v.size() != 3 || !std::all_of(v.begin(), v.end(), [](const json& x) { return x.is_number(); })) {
      fail(line, "\"" + key + "\": must be 3 numbers");
    }
    return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
  }

  void read_camera(Job& job, const json& c) const {
    if (!c.is_object()) fail(job.line, "\"camera\": must be an object");
    for (const auto& [key, v] : c.items()) {
      const std::string where = "camera." + key;
      if (key == "position") job.camera.position = vec3(v, job.line, where);
      else if (key == "look_at") job.camera.look_at = vec3(v, job.line, where);
      else if (key == "up") job.camera.up = vec3(v, job.line, where);
      else if (key == "fov_y") {
        if (!v.is_number()) fail(job.line, "\"camera.fov_y\": must be a number");
        job.camera.fov_y = v.get<double>();
      } else if (key == "width") job.camera.width = integer(v, job.line, where);
      else if (key == "height") job.camera.height = integer(v, job.line, where);
      else fail(job.line, quote(where) + ": unknown key (position, look_at, up, fov_y, width, height)");
    }
  }

  void read_key(Job& job, const std::string& key, const json& v) const {
    if (key == "scene") job.scene = path(v, job.line, "scene");
    else if (key == "out") job.out = path(v, job.line, "out");
    else if (key == "stats") job.stats = path(v, job.line, "stats");
    else if (key == "method") {
      if (!v.is_string()) fail(job.line, "\"method\": must be a string");
      job.method = v.get<std::string>();
    } else if (key == "cube_res") job.cube_res = integer(v, job.line, key);
    else if (key == "max_depth") job.max_depth = integer(v, job.line, key);
    else if (key == "camera") read_camera(job, v);
    else if (key == "aovs") {
      if (!v.is_array()) fail(job.line, "\"aovs\": must be a list of names");
      for (const json& a : v) {
        if (!a.is_string()) fail(job.line, "\"aovs\": must be a list of names");
        job.aovs.push_back(a.get<std::string>());
      }
    } else {
      fail(job.line, quote(key) + ": unknown key (scene, out, method, cube_res, max_depth, camera, stats, aovs)");
    }
  }

  std::string file_;
  fs::path dir_;
};

}  // namespace

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
