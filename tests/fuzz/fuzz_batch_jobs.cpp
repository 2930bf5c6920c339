// libFuzzer harness: the bytes are a jobs file of `abcube batch` (cli.md "Batch"), read by
// read_jobs (host/cli/batch_jobs.cpp) as "/jobs/jobs.jsonl" whole and as shard 1/3. Every
// job returned has a scene and an output, a line number within the file, and lines in
// increasing order; an error names "/jobs/jobs.jsonl:LINE:" with a line of the file.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "cli/batch_jobs.hpp"
#include "fuzz_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace fz = abcube::fuzz;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string file = "/jobs/jobs.jsonl";
  const size_t lines = static_cast<size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
  for (const size_t shard_n : {size_t{1}, size_t{3}}) {
    std::istringstream in(text);
    try {
      const std::vector<abcube::Job> jobs = abcube::read_jobs(in, file, shard_n - 1, shard_n);
      size_t last = 0;
      for (const abcube::Job& job : jobs) {
        if (job.scene.empty() || job.out.empty()) fz::broken("a job without its scene or output");
        if (job.scene.rfind("/", 0) != 0 || job.out.rfind("/", 0) != 0) fz::broken("a path not resolved: " + job.out);
        if (job.line <= last || job.line > lines) fz::broken("job line " + std::to_string(job.line) + " out of order");
        last = job.line;
      }
    } catch (const abcube::InputError& e) {
      const std::string message = e.what();
      fz::check_message(message, file);
      size_t line = 0;  // "FILE:LINE: ..."
      for (size_t i = file.size() + 1; i < message.size() && message[i] >= '0' && message[i] <= '9' && line < lines + 1;
           ++i) {
        line = 10 * line + static_cast<size_t>(message[i] - '0');
      }
      if (line == 0 || line > lines)
        fz::broken("error names line " + std::to_string(line) + " of " + std::to_string(lines));
    } catch (const std::exception& e) {
      fz::broken(std::string("not an InputError: ") + e.what());
    }
  }
  return 0;
}
