// abcube compare A B: image error figures and idiff-like thresholds (metrics.hpp).
//   exit 0 within thresholds, 1 beyond, 2 for bad input (unreadable file, size mismatch).
//   --exact: exit 0 only when every channel of every pixel holds the same float.
#include <cmath>
#include <cstdio>

#include "cli/cli_common.hpp"
#include "base/error.hpp"
#include "io/image_io.hpp"
#include "io/metrics.hpp"

namespace abcube {

int cmd_compare(const std::vector<std::string>& words) {
  const Args args(words, {"--diff", "--fail", "--failpercent"}, {"--exact"});
  args.expect_positional(2, "images A and B");
  // A pixel fails when its largest channel differs by more than --fail (displayed values,
  // 0..1; default one 8-bit code); the comparison fails when more than --failpercent
  // percent of pixels fail (default 0).
  const double fail = args.get_double("--fail", 1.0 / 255.0, 0.0, 1.0);
  const double fail_percent = args.get_double("--failpercent", 0.0, 0.0, 100.0);
  const std::string diff_path = args.get("--diff");
  if (!diff_path.empty() && !image_format_supported(diff_path)) {
    throw InputError(diff_path + ": no image writer for this file extension");
  }
  const Image a = read_image(args.positional()[0]);
  const Image b = read_image(args.positional()[1]);
  if (a.width != b.width || a.height != b.height) {
    throw InputError(args.positional()[0] + " is " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                     ", " + args.positional()[1] + " is " + std::to_string(b.width) + "x" +
                     std::to_string(b.height) + ": sizes differ");
  }
  if (args.has("--exact")) {
    // Bit for bit: the same channels and the same float in every one (before any encoding).
    const bool same = a.channels == b.channels && a.data == b.data;
    std::printf("%s\n", same ? "IDENTICAL" : "DIFFERENT");
    return same ? 0 : 1;
  }
  const ImageError e = image_error(a, b);
  const double failing = share_over(a, b, fail);
  std::printf("RMSE        %.6g\n", e.rmse);
  if (std::isfinite(e.psnr)) {
    std::printf("PSNR        %.2f dB\n", e.psnr);
  } else {
    std::printf("PSNR        inf (identical)\n");
  }
  std::printf("max abs     %.6g (%.1f/255)\n", e.max_abs, e.max_abs * 255.0);
  std::printf("over 1/255  %.4f%% of pixels\n", 100.0 * e.share_over_1);
  std::printf("over 2/255  %.4f%% of pixels\n", 100.0 * e.share_over_2);
  std::printf("over --fail %.6g: %.4f%% of pixels (allowed %.4f%%)\n", fail, 100.0 * failing, fail_percent);
  if (!diff_path.empty()) write_image(diff_path, error_heatmap(a, b));
  const bool pass = 100.0 * failing <= fail_percent;
  std::printf("%s\n", pass ? "PASS" : "FAIL");
  return pass ? 0 : 1;
}

}  // namespace abcube
