// The comparison report (`abcube report`, abcube.report): one scene rendered by several
// methods and by the exact tracer, each method's error against it, where and on what
// surfaces that error lies, what each took, a sweep of speed against error, and the GPU
// against the CPU; written as one self-contained page a person can look at.
//
//   DIR/index.html      the page: works offline (no network, no CDN), images beside it,
//                       plots as inline SVG
//   DIR/report.json     every figure the page shows, under the same keys
//   DIR/images/*.png    each method's image, its heat map against the reference (with its
//                       legend), the reference, the crosscheck's disagreement overlay
//   DIR/stats/*.json    each render's stats (as `abcube render --stats` writes them)
//
// A tool over the library, in a library of its own: link abcube::report (find_package(abcube)).
#pragma once
#include <functional>
#include <string>
#include <vector>

#include <abcube/renderer.hpp>
#include <abcube/scene.hpp>

namespace abcube {

struct ReportOptions {
  // The methods compared with the exact tracer (raytrace is the reference, always rendered).
  std::vector<std::string> methods = {"abuffer", "gpu", "hybrid", "zbuffer", "envmap"};
  // Cube map resolutions N at which abuffer is rendered again for the plot of error against
  // time (empty: no sweep).
  std::vector<int> sweep;
  // Options of every render (size, camera, depth, threads, ...); each method's render takes
  // those it uses (without_unused_options, <abcube/renderer.hpp>).
  RenderOptions render;
  RendererOptions renderer;
  // The GPU against the CPU (`abcube crosscheck`), where a GL path works.
  bool crosscheck = true;
  // Called with a line for each step ("rendering abuffer"), or null.
  std::function<void(const std::string&)> progress;
};

struct ReportResult {
  std::string index_html;  // DIR/index.html
  std::string json;        // the content of DIR/report.json
  int methods_failed = 0;  // methods that could not render here (no GL for gpu, ...): on the page with why
};

// Renders and writes the report into `dir` (made if missing; the files above replaced, the
// page last, each written whole). InputError for a bad option or method name; a method that
// fails to render is on the page with its reason, not an exception.
ReportResult write_report(const Scene& scene, const std::string& dir, const ReportOptions& options);

}  // namespace abcube
