// The jobs file of `abcube batch` (cli.md "Batch"): one JSON object per line, read and
// checked whole before anything renders. Separate from the command so that the fuzz
// harness (tests/fuzz/fuzz_batch_jobs.cpp) reads jobs through the same code.
#pragma once
#include <cstddef>
#include <istream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <abcube/options.hpp>
#include <abcube/renderer.hpp>

namespace abcube {

// A jobs file line holds one small JSON object; a longer line (/dev/zero has no line
// break at all) is refused as soon as it passes this.
constexpr size_t MAX_JOB_LINE_BYTES = size_t{1} << 20;

// One line of the jobs file, paths resolved against the file's folder.
struct Job {
  size_t line = 0;
  std::string scene, out, stats;
  // Every other key: a render option of the table (<abcube/options.hpp>), checked, as its
  // key and its value's JSON text, in the line's order; "camera" {...} is given as its
  // keys (fov_y, camera_position, ...), "set" as one object.
  std::vector<std::pair<std::string, std::string>> options;
  // The job's own settings over `base` (the command line's).
  RenderSetup setup(const RenderSetup& base) const;
};

// Every job of `in` (the file named `jobs_path`, whose folder resolves relative paths),
// checked; only those whose 0-based index modulo `shard_n` is `shard_i` are returned.
// InputError "JOBS_PATH:LINE: reason" for the first malformed line.
std::vector<Job> read_jobs(std::istream& in, const std::string& jobs_path, size_t shard_i = 0, size_t shard_n = 1);

}  // namespace abcube
