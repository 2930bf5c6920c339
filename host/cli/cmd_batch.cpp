// abcube batch JOBS.jsonl: many renders in one process through one Renderer (cli.md
// "Batch"). The whole jobs file is read and checked before anything renders (a malformed
// line: exit 2, naming it); GL is opened once and each distinct scene loaded once; a job
// that fails is one stderr line, JOBS.jsonl:LINE: reason, and the others go on (exit 1).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <list>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <abcube/renderer.hpp>

#include "base/error.hpp"
#include "base/input_file.hpp"
#include "base/parallel.hpp"
#include "base/statistics.hpp"
#include "base/temporary_file.hpp"
#include "base/timer.hpp"
#include "cli/batch_jobs.hpp"
#include "cli/cli_common.hpp"
#include "io/image_io.hpp"

namespace abcube {

namespace {

namespace fs = std::filesystem;

// The scenes of the batch, each loaded once; the least recently used dropped past `capacity`.
class SceneShelf {
 public:
  explicit SceneShelf(size_t capacity, SceneLimits limits) : capacity_(capacity), limits_(std::move(limits)) {}
  // The scene at `path` with the values `set` replaced: each distinct pair is loaded once.
  Scene get(const std::string& path, const SceneOverrides& set) {
    std::string key = path;
    for (const SceneOverride& o : set) key += "\n" + o.path + "=" + o.value;
    for (auto it = scenes_.begin(); it != scenes_.end(); ++it) {
      if (it->first == key) {
        scenes_.splice(scenes_.begin(), scenes_, it);
        return it->second;
      }
    }
    scenes_.emplace_front(key, Scene::load(path, limits_, set));
    if (scenes_.size() > capacity_) scenes_.pop_back();
    ++loads_;
    return scenes_.front().second;
  }
  size_t loads() const { return loads_; }

 private:
  size_t capacity_;
  SceneLimits limits_;
  std::list<std::pair<std::string, Scene>> scenes_;
  size_t loads_ = 0;
};

// "[=====     ] 12/64 jobs, 1 failed" on a terminal, redrawn in place.
void draw_progress(size_t done, size_t total, size_t failed) {
  constexpr int WIDTH = 30;
  const int filled = total ? static_cast<int>(WIDTH * done / total) : WIDTH;
  std::fprintf(stderr, "\r[%s%s] %zu/%zu jobs%s", std::string(static_cast<size_t>(filled), '=').c_str(),
               std::string(static_cast<size_t>(WIDTH - filled), ' ').c_str(), done, total,
               failed ? (", " + std::to_string(failed) + " failed").c_str() : "");
  if (done == total) std::fputc('\n', stderr);
}

// Whether every output of `job` exists: its image, each AOV it asks for and its stats
// (--skip-existing). Each lands whole, by rename: a file there is complete.
bool outputs_exist(const Job& job, const RenderSetup& base) {
  if (!fs::exists(job.out) || (!job.stats.empty() && !fs::exists(job.stats))) return false;
  std::vector<std::string> aovs;
  try {
    aovs = job.setup(base).render.aovs;
  } catch (const std::exception&) {
    return false;  // the render says what is wrong
  }
  for (const std::string& name : aovs) {
    if (!fs::exists(aov_path(job.out, name))) return false;
  }
  return true;
}

// The options a job names itself that its method does not use, refused as `render` refuses
// them, before anything renders (exit 2), wherever the job or the command line names the
// method; a job whose method is its scene's is checked when it renders (job_setup).
void check_own_options(const Job& job, const RenderSetup& base, const std::string& jobs_path) {
  const RenderSetup own = job.setup(RenderSetup{});
  const std::string method = own.render.method.empty() ? base.render.method : own.render.method;
  if (method.empty()) return;
  try {
    refuse_options_unused_by(method, own.render);
  } catch (const OptionError& e) {
    throw InputError(jobs_path + ":" + std::to_string(job.line) + ": \"" + e.key + "\": " + one_line(e.reason, "; "));
  }
}

// A job's settings: the command line's defaults that its method uses, then its own keys.
// A default its method does not use (--cube-res for a raytrace job) is left out for that job;
// a key the job names itself that its method does not use is refused.
RenderSetup job_setup(const Job& job, const RenderSetup& base, const Scene& scene) {
  const std::string method = job.setup(base).render.method;
  RenderSetup defaults = base;
  defaults.render = without_unused_options(base.render, method.empty() ? scene.method() : method);
  defaults.render.method = base.render.method;
  const RenderSetup own = job.setup(RenderSetup{});
  refuse_unused_options(scene, [&] {
    RenderOptions o = own.render;
    if (o.method.empty()) o.method = base.render.method;
    return o;
  }());
  return job.setup(defaults);
}

struct BatchCommand {
  std::string jobs_path, shard = "0/1";
  bool skip_existing = false;
  double job_timeout_s = 0;
  size_t scene_cache = 4;
  RenderFlags flags;

  std::pair<size_t, size_t> parse_shard() const {
    size_t i = 0, n = 0;
    char slash = 0;
    std::istringstream in(shard);
    if (!(in >> i >> slash >> n) || slash != '/' || !in.eof() || n == 0 || i >= n) {
      throw InputError("--shard: must be I/N with 0 <= I < N, got " + quote(shard));
    }
    return {i, n};
  }

  // Every job of the file, checked; only this shard's are returned.
  std::vector<Job> read_jobs(size_t shard_i, size_t shard_n) const {
    std::ifstream in(jobs_path);
    if (!in) throw InputError(jobs_path + ": cannot read the jobs file");
    return abcube::read_jobs(in, jobs_path, shard_i, shard_n);
  }

  // Every job's outputs and own options, before anything renders, as a malformed line is.
  void check_jobs(const std::vector<Job>& jobs, const RenderSetup& base) const {
    for (const Job& job : jobs) {
      for (const auto& [key, out] :
           {std::pair<const char*, const std::string*>{"out", &job.out}, {"stats", &job.stats}}) {
        try {
          check_output_path(*out, out == &job.out);
        } catch (const InputError& e) {
          throw InputError(jobs_path + ":" + std::to_string(job.line) + ": \"" + key + "\": " + e.what());
        }
      }
      check_own_options(job, base, jobs_path);
    }
  }

  // What killed runs left (SIGKILL, a preempted machine) in the jobs' output folders: their
  // temporaries, once their processes are gone. Every output lands whole, by rename, so what
  // exists is complete. Returns how many were removed.
  static size_t clear_killed_runs(const std::vector<Job>& jobs) {
    size_t stale = 0;
    std::set<std::string> folders;
    for (const Job& job : jobs) {
      for (const std::string* out : {&job.out, &job.stats}) {
        if (!out->empty() && folders.insert(fs::path(*out).parent_path().string()).second)
          stale += remove_stale_temporaries(fs::path(*out).parent_path().string());
      }
    }
    return stale;
  }

  int run() const {
    const Clock::time_point start = Clock::now();
    const auto [shard_i, shard_n] = parse_shard();
    RenderSetup base = flags.setup();
    if (job_timeout_s > 0) base.render.timeout_s = job_timeout_s;
    const std::vector<Job> jobs = read_jobs(shard_i, shard_n);
    check_jobs(jobs, base);
    const size_t stale = clear_killed_runs(jobs);
    Renderer renderer(base.renderer);
    SceneShelf scenes(std::max<size_t>(scene_cache, 1), base.limits);
    const bool terminal = stderr_is_terminal();
    size_t done = 0, failed = 0, skipped = 0;
    std::vector<double> render_ms, overhead_ms;
    std::set<std::string> warned;  // scenes whose warnings were printed
    // SIGINT or SIGTERM (a stop request): the job under way leaves nothing, the batch ends
    // here, and --skip-existing resumes it.
    auto stopped = [&] {
      if (terminal) std::fputc('\n', stderr);
      std::fprintf(stderr, "%s: stopped after %zu of %zu jobs (%zu rendered); rerun with --skip-existing to resume\n",
                   jobs_path.c_str(), done, jobs.size(), render_ms.size());
    };
    for (const Job& job : jobs) {
      if (stop_requested()) {
        stopped();
        check_stop_request();
      }
      if (skip_existing && outputs_exist(job, base)) {
        ++skipped;
      } else {
        try {
          const Clock::time_point t0 = Clock::now();
          const Scene scene = scenes.get(job.scene, job.setup(base).set);
          const RenderSetup setup = job_setup(job, base, scene);
          const RenderResult r = renderer.render(scene, setup.render);
          make_output_folders({job.out, job.stats});
          write_outputs(job.out, r);
          if (!job.stats.empty()) write_text_atomic(job.stats, r.stats.json + "\n");
          render_ms.push_back(ms_since(t0));
          if (warned.insert(job.scene).second && !scene.warnings().empty()) {
            if (terminal) std::fputc('\n', stderr);
            print_warnings(scene, jobs_path + ":" + std::to_string(job.line) + ": ");
          }
        } catch (const Interrupted&) {
          stopped();
          throw;
        } catch (const OptionError& e) {  // named as the line names it
          ++failed;
          if (terminal) std::fputc('\n', stderr);
          std::fprintf(stderr, "%s:%zu: %s: %s\n", jobs_path.c_str(), job.line, quote(e.key).c_str(),
                       one_line(e.reason, "; ").c_str());
        } catch (const std::exception& e) {
          ++failed;
          if (terminal) std::fputc('\n', stderr);
          std::fprintf(stderr, "%s:%zu: %s\n", jobs_path.c_str(), job.line, one_line(e.what(), "; ").c_str());
        }
      }
      ++done;
      if (terminal) draw_progress(done, jobs.size(), failed);
    }
    const double total_ms = ms_since(start);
    std::vector<double> sorted = render_ms;
    const double median = sorted.empty() ? 0.0 : percentile(sorted, 0.5);
    std::printf(
        "batch %s shard %zu/%zu: %zu jobs, %zu rendered, %zu failed, %zu skipped; %zu scenes loaded; "
        "%.1f ms per render (median, with load and write), %.1f s in all%s\n",
        jobs_path.c_str(), shard_i, shard_n, jobs.size(), render_ms.size(), failed, skipped, scenes.loads(), median,
        total_ms / 1000.0, stale ? ("; " + std::to_string(stale) + " temporaries of killed runs removed").c_str() : "");
    return failed ? 1 : 0;
  }
};

}  // namespace

CommandRun add_batch_command(CLI::App& app) {
  auto c = std::make_shared<BatchCommand>();
  CLI::App* cmd = app.add_subcommand(
      "batch",
      "many renders in one process: one JSON job per line, {\"scene\": ..., \"out\": ...} plus optional stats (a "
      "path), camera (an object) and any render option below by its snake_case name (cube_res, set, ...); paths "
      "relative to the jobs file");
  cmd->add_option("JOBS", c->jobs_path, "jobs file (JSON lines)")->required()->type_name("PATH");
  cmd->add_option("--shard", c->shard, "render the jobs whose 0-based index modulo N is I (default: 0/1, every job)")
      ->type_name("I/N");
  cmd->add_flag("--skip-existing", c->skip_existing,
                "skip jobs whose outputs all exist: image, AOVs and stats (resume an interrupted or killed batch)");
  cmd->add_option("--job-timeout", c->job_timeout_s,
                  "stop one job past this many seconds, and go on with the next (seconds, 0 to 1e9; default: 0, no "
                  "limit). --timeout, by contrast, applies to every job as a render option")
      ->type_name("NUMBER")
      ->check(CLI::Range(0.0, 1e9).description(""));
  cmd->add_option("--scene-cache", c->scene_cache,
                  "distinct scenes kept loaded at once, the least recently used dropped (scenes, 1 to 1048576; "
                  "default: 4)")
      ->type_name("INT")
      ->check(CLI::Range(1, 1 << 20).description(""));
  c->flags.add_to(cmd);
  return [c] { return c->run(); };
}

}  // namespace abcube
