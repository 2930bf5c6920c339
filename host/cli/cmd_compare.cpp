// abcube compare A B: image error figures and idiff-like thresholds (metrics.hpp).
//   exit 0 within thresholds, 1 beyond, 2 for bad input (unreadable file, size mismatch).
//   --exact: exit 0 only when every channel of every pixel holds the same float.
#include <cmath>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli/cli_common.hpp"
#include "base/error.hpp"
#include "io/image_io.hpp"
#include "io/metrics.hpp"
#include "render/stats_json.hpp"

namespace abcube {

namespace {

struct CompareCommand {
  std::string a, b, diff_path;
  // A pixel fails when its largest channel differs by more than `fail` (displayed values,
  // 0..1; default one 8-bit code); the comparison fails when more than `fail_percent`
  // percent of pixels fail (default 0).
  double fail = 1.0 / 255.0, fail_percent = 0.0;
  bool exact = false, json_output = false;

  int run() const {
    check_output_path(diff_path, true);
    const Image ia = read_image(a);
    const Image ib = read_image(b);
    if (ia.width != ib.width || ia.height != ib.height) {
      throw InputError(a + " is " + std::to_string(ia.width) + "x" + std::to_string(ia.height) + ", " + b + " is " +
                       std::to_string(ib.width) + "x" + std::to_string(ib.height) + ": sizes differ");
    }
    if (exact) {
      // Bit for bit: the same channels and the same float in every one (before any encoding).
      const bool same = ia.channels == ib.channels && ia.data == ib.data;
      std::printf("%s\n", same ? "IDENTICAL" : "DIFFERENT");
      return same ? 0 : 1;
    }
    const ImageError e = image_error(ia, ib);
    const double failing = share_over(ia, ib, fail);
    const bool pass = 100.0 * failing <= fail_percent;
    if (!diff_path.empty()) write_image(diff_path, with_heatmap_legend(error_heatmap(ia, ib)));
    if (json_output) {
      nlohmann::json j = image_error_json(e);
      j["a"] = a;
      j["b"] = b;
      j["width"] = ia.width;
      j["height"] = ia.height;
      j["fail"] = {{"threshold", fail}, {"share", failing}, {"allowed_percent", fail_percent}};
      j["pass"] = pass;
      std::printf("%s\n", j.dump(2).c_str());
      return pass ? 0 : 1;
    }
    // The verdict first, with the test that gave it: a bare comparison fails on one pixel
    // over 1/255, which a reader of its last line alone would take for "far apart".
    std::printf(
        "%s: %.4f%% of pixels differ by more than %.4g (--fail, displayed values), %.4g%% allowed "
        "(--failpercent)\n",
        pass ? "PASS" : "FAIL", 100.0 * failing, fail, fail_percent);
    std::printf("RMSE        %.6g\n", e.rmse);
    if (std::isfinite(e.psnr)) {
      std::printf("PSNR        %.2f dB\n", e.psnr);
    } else {
      std::printf("PSNR        inf (identical)\n");
    }
    std::printf("max abs     %.6g (%.1f/255) at (%d, %d, %c): %.6g against %.6g (linear)\n", e.max_abs,
                e.max_abs * 255.0, e.worst_x, e.worst_y, "RGB"[e.worst_channel], e.worst_a[e.worst_channel],
                e.worst_b[e.worst_channel]);
    std::printf("over 1/255  %.4f%% of pixels\n", 100.0 * e.share_over_1);
    std::printf("over 2/255  %.4f%% of pixels\n", 100.0 * e.share_over_2);
    std::printf("over 8/255  %.4f%% of pixels\n", 100.0 * e.share_over_8);
    std::printf("linear      RMSE %.6g, max abs %.6g, mean relative %.6g%s\n", e.linear_rmse, e.linear_max_abs,
                e.relative_mean, e.hdr ? " (values above 1: the displayed figures above clamp them)" : "");
    std::printf("over --fail %.6g: %.4f%% of pixels (allowed %.4f%%)\n", fail, 100.0 * failing, fail_percent);
    std::printf("%s\n", pass ? "PASS" : "FAIL");
    return pass ? 0 : 1;
  }
};

}  // namespace

CommandRun add_compare_command(CLI::App& app) {
  auto c = std::make_shared<CompareCommand>();
  CLI::App* cmd = app.add_subcommand("compare", "RMSE, PSNR, max abs error and the share of pixels over a threshold");
  cmd->add_option("A", c->a, "first image")->required()->type_name("IMAGE");
  cmd->add_option("B", c->b, "second image")->required()->type_name("IMAGE");
  cmd->add_option("--diff", c->diff_path,
                  "write a per-pixel error heat map here, its legend beneath (black 0 ... red 128/255)")
      ->type_name("PATH");
  cmd->add_option("--fail", c->fail, "a pixel fails above this difference of displayed values (0 to 1; default: 1/255)")
      ->type_name("NUMBER")
      ->check(CLI::Range(0.0, 1.0).description(""));
  cmd->add_option("--failpercent", c->fail_percent,
                  "the comparison fails (exit 1) above this share of failing pixels (%, 0 to 100; default: 0, any "
                  "failing pixel fails it; 100: the figures alone, always exit 0)")
      ->type_name("NUMBER")
      ->check(CLI::Range(0.0, 100.0).description(""));
  cmd->add_flag("--exact", c->exact, "pass only when every float is the same (bit for bit, before encoding)");
  cmd->add_flag("--json", c->json_output, "print every figure as one JSON object instead of the text");
  return [c] { return c->run(); };
}

}  // namespace abcube
