// The report's page, drawn from report.json's content (report_html.hpp).
#include "render/report_html.hpp"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

namespace abcube {

namespace {

using nlohmann::json;

std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string fixed(double x, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, x);
  return text;
}

// A figure of report.json at `key` (dots between keys), shown with `decimals` decimals
// (scaled by `scale`: 100 for a share shown in percent), as data-key and data-value.
std::string figure(const json& report, const std::string& key, int decimals, double scale = 1, const char* tag = "td") {
  const json* v = &report;
  std::stringstream path(key);
  const std::string none = std::string("<") + tag + ">-</" + tag + ">";
  for (std::string part; std::getline(path, part, '.');) {
    if (v->is_array()) {  // an index: sweep.points.0.total_ms
      const size_t i =
          part.find_first_not_of("0123456789") == std::string::npos && !part.empty() ? std::stoul(part) : SIZE_MAX;
      if (i >= v->size()) return none;
      v = &(*v)[i];
      continue;
    }
    if (!v->is_object() || !v->contains(part)) return none;
    v = &(*v)[part];
  }
  const std::string shown = v->is_number() ? fixed(v->get<double>() * scale, decimals) : escape(v->dump());
  return std::string("<") + tag + " class=\"num\" data-key=\"" + escape(key) + "\" data-value=\"" + escape(v->dump()) +
         "\" data-scale=\"" + fixed(scale, 0) + "\" data-decimals=\"" + std::to_string(decimals) + "\">" + shown +
         "</" + tag + ">";
}

std::vector<std::string> method_order(const json& report) {
  std::vector<std::string> names;
  for (const json& name : report.value("method_order", json::array())) {
    if (report.contains("methods") && report["methods"].contains(name.get<std::string>())) names.push_back(name);
  }
  return names;
}

// A scatter plot as inline SVG: points (x, y) with labels, linear axes with their names;
// optional curve (x, y) drawn as a line, and a log10 y axis when `log_y`.
struct Plot {
  std::string title, x_name, y_name;
  std::vector<std::pair<double, double>> points;
  std::vector<std::string> labels;
  std::vector<std::pair<double, double>> curve;
  std::string curve_name;
  bool log_y = false, log_x = false;
  std::vector<std::string> curve_labels;  // beside the curve's points, drawn as dots when given
  std::vector<bool> front, curve_front;   // points and curve points on the Pareto front, ringed and joined
  std::string id;                         // the svg element's id
};

// The Pareto front of a plot: its points and curve points flagged, ringed and joined left to
// right, through the plot's scales.
template <class SX, class SY, class Finite>
std::string front_marks(const Plot& p, SX sx, SY sy, Finite finite) {
  std::string s, front;
  std::vector<std::pair<double, double>> on;
  for (const auto& [xs, flags] : {std::pair{&p.points, &p.front}, std::pair{&p.curve, &p.curve_front}}) {
    for (size_t i = 0; i < xs->size() && i < flags->size(); ++i) {
      if ((*flags)[i] && finite((*xs)[i].first, (*xs)[i].second)) on.push_back((*xs)[i]);
    }
  }
  std::sort(on.begin(), on.end());
  for (const auto& [x, y] : on) {
    front += (front.empty() ? "M" : " L") + fixed(sx(x), 1) + " " + fixed(sy(y), 1);
    s += "<circle class=\"front\" cx=\"" + fixed(sx(x), 1) + "\" cy=\"" + fixed(sy(y), 1) +
         "\" r=\"8\" fill=\"none\" stroke=\"#2a8a2a\" stroke-width=\"2\"/>";
  }
  if (on.size() > 1) s += "<path d=\"" + front + "\" fill=\"none\" stroke=\"#2a8a2a\" stroke-width=\"1.5\"/>";
  return s;
}

std::string svg(const Plot& p) {
  constexpr double W = 520, H = 300, L = 64, R = 16, T = 28, B = 44;
  std::vector<std::pair<double, double>> all = p.points;
  all.insert(all.end(), p.curve.begin(), p.curve.end());
  const auto tx = [&](double v) { return p.log_x ? std::log10(std::max(v, 1e-30)) : v; };
  const auto ty = [&](double v) { return p.log_y ? std::log10(std::max(v, 1e-30)) : v; };
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const auto& [x, y] : all) {
    if (!std::isfinite(tx(x)) || !std::isfinite(ty(y))) continue;
    x0 = std::min(x0, tx(x)), x1 = std::max(x1, tx(x)), y0 = std::min(y0, ty(y)), y1 = std::max(y1, ty(y));
  }
  if (!(x0 <= x1)) x0 = 0, x1 = 1;
  if (!(y0 <= y1)) y0 = 0, y1 = 1;
  const double dx = std::max(x1 - x0, 1e-9) * 0.08, dy = std::max(y1 - y0, 1e-9) * 0.1;
  x0 -= dx, x1 += dx, y0 -= dy, y1 += dy;
  const auto sx = [&](double v) { return L + (tx(v) - x0) / (x1 - x0) * (W - L - R); };
  const auto sy = [&](double v) { return H - B - (ty(v) - y0) / (y1 - y0) * (H - T - B); };
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\"" + (p.id.empty() ? "" : " id=\"" + escape(p.id) + "\"") +
                  " width=\"" + fixed(W, 0) + "\" height=\"" + fixed(H, 0) + "\" viewBox=\"0 0 " + fixed(W, 0) + " " +
                  fixed(H, 0) + "\" role=\"img\"><title>" + escape(p.title) +
                  "</title><rect width=\"100%\" height=\"100%\" fill=\"#fff\"/>";
  s += "<text x=\"" + fixed(W / 2, 0) + "\" y=\"18\" text-anchor=\"middle\" font-size=\"13\">" + escape(p.title) +
       "</text>";
  s += "<line x1=\"" + fixed(L, 0) + "\" y1=\"" + fixed(H - B, 0) + "\" x2=\"" + fixed(W - R, 0) + "\" y2=\"" +
       fixed(H - B, 0) + "\" stroke=\"#333\"/><line x1=\"" + fixed(L, 0) + "\" y1=\"" + fixed(T, 0) + "\" x2=\"" +
       fixed(L, 0) + "\" y2=\"" + fixed(H - B, 0) + "\" stroke=\"#333\"/>";
  for (int i = 0; i <= 4; ++i) {  // ticks: 5 on each axis, in the axis' own units
    const double vx = x0 + (x1 - x0) * i / 4, vy = y0 + (y1 - y0) * i / 4;
    const double px = L + (W - L - R) * i / 4, py = H - B - (H - T - B) * i / 4;
    const double lx = p.log_x ? std::pow(10, vx) : vx, ly = p.log_y ? std::pow(10, vy) : vy;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", lx);
    s += "<text x=\"" + fixed(px, 1) + "\" y=\"" + fixed(H - B + 16, 0) +
         "\" text-anchor=\"middle\" font-size=\"11\">" + buf + "</text>";
    std::snprintf(buf, sizeof buf, "%.3g", ly);
    s += "<text x=\"" + fixed(L - 6, 0) + "\" y=\"" + fixed(py + 4, 1) + "\" text-anchor=\"end\" font-size=\"11\">" +
         buf + "</text>";
  }
  s += "<text x=\"" + fixed((L + W - R) / 2, 0) + "\" y=\"" + fixed(H - 8, 0) +
       "\" text-anchor=\"middle\" font-size=\"12\">" + escape(p.x_name) + "</text>";
  s += "<text x=\"14\" y=\"" + fixed((T + H - B) / 2, 0) +
       "\" text-anchor=\"middle\" font-size=\"12\" transform=\"rotate(-90 14 " + fixed((T + H - B) / 2, 0) + ")\">" +
       escape(p.y_name) + "</text>";
  if (!p.curve.empty()) {
    std::string d;
    for (const auto& [x, y] : p.curve) d += (d.empty() ? "M" : " L") + fixed(sx(x), 1) + " " + fixed(sy(y), 1);
    s += "<path d=\"" + d + "\" fill=\"none\" stroke=\"#c33\" stroke-dasharray=\"5 3\"/>";
    s += "<text x=\"" + fixed(W - R - 4, 0) + "\" y=\"" + fixed(T + 14, 0) +
         "\" text-anchor=\"end\" font-size=\"11\" fill=\"#c33\">" + escape(p.curve_name) + "</text>";
    for (size_t i = 0; i < p.curve_labels.size() && i < p.curve.size(); ++i) {
      const auto& [x, y] = p.curve[i];
      s += "<circle class=\"rung\" cx=\"" + fixed(sx(x), 1) + "\" cy=\"" + fixed(sy(y), 1) +
           "\" r=\"3\" fill=\"#c33\"/>";
      s += "<text x=\"" + fixed(sx(x) + 5, 1) + "\" y=\"" + fixed(sy(y) + 12, 1) +
           "\" font-size=\"10\" fill=\"#c33\">" + escape(p.curve_labels[i]) + "</text>";
    }
  }
  s += front_marks(p, sx, sy, [&](double x, double y) { return std::isfinite(tx(x)) && std::isfinite(ty(y)); });
  for (size_t i = 0; i < p.points.size(); ++i) {
    const auto& [x, y] = p.points[i];
    if (!std::isfinite(tx(x)) || !std::isfinite(ty(y))) continue;
    s += "<circle class=\"point\" cx=\"" + fixed(sx(x), 1) + "\" cy=\"" + fixed(sy(y), 1) +
         "\" r=\"4\" fill=\"#1f5fbf\"/>";
    if (i < p.labels.size()) {
      s += "<text x=\"" + fixed(sx(x) + 6, 1) + "\" y=\"" + fixed(sy(y) - 6, 1) + "\" font-size=\"11\">" +
           escape(p.labels[i]) + "</text>";
    }
  }
  return s + "</svg>";
}

const char* STYLE = R"css(
body { font: 14px/1.45 system-ui, sans-serif; margin: 24px; color: #222; background: #fafafa; }
h1 { font-size: 22px; margin: 0 0 4px; } h2 { font-size: 18px; margin: 28px 0 8px; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 8px 0; background: #fff; } td, th { border: 1px solid #ddd; padding: 3px 8px; }
th { background: #f0f0f0; text-align: left; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
.gallery { display: flex; flex-wrap: wrap; gap: 16px; } figure { margin: 0; } figcaption { font-size: 12px; color: #555; }
img.px { image-rendering: pixelated; display: block; }
.viewer { position: relative; display: inline-block; overflow: auto; max-width: 100%; max-height: 80vh; border: 1px solid #999; background: #000; }
.viewer .layer { position: absolute; left: 0; top: 0; } .viewer .base { position: relative; }
.controls { margin: 8px 0; display: flex; gap: 12px; align-items: center; flex-wrap: wrap; }
.pass { color: #186a1e; font-weight: bold; } .fail { color: #b00; font-weight: bold; } .note { color: #555; font-size: 12px; }
)css";

// The viewer and the page's own checks: every image loaded (data-images-loaded and
// data-images-broken on <body>) and no script error (data-errors), for a test to read.
const char* SCRIPT = R"js(
(function () {
  var body = document.body, errors = 0;
  window.addEventListener('error', function () { errors += 1; body.setAttribute('data-errors', String(errors)); });
  body.setAttribute('data-errors', '0');
  function $(id) { return document.getElementById(id); }
  var a = $('pick-a'), b = $('pick-b'), wipe = $('wipe'), zoom = $('zoom'), flip = $('flip');
  var top = $('view-a'), base = $('view-b'), label = $('view-label');
  function size() {
    var z = Number(zoom.value), w = base.naturalWidth * z, h = base.naturalHeight * z;
    [top, base].forEach(function (img) { img.style.width = w + 'px'; img.style.height = h + 'px'; });
    top.style.clipPath = 'inset(0 ' + (100 - Number(wipe.value)) + '% 0 0)';
  }
  function show() {
    top.src = a.value; base.src = b.value;
    label.textContent = a.options[a.selectedIndex].text + ' (left of the line) | ' + b.options[b.selectedIndex].text + ' (right)';
  }
  [top, base].forEach(function (img) { img.addEventListener('load', size); });
  a.addEventListener('change', show); b.addEventListener('change', show);
  wipe.addEventListener('input', size); zoom.addEventListener('change', size);
  flip.addEventListener('click', function () { var t = a.selectedIndex; a.selectedIndex = b.selectedIndex; b.selectedIndex = t; show(); });
  Array.prototype.forEach.call(document.querySelectorAll('[data-pick]'), function (el) {
    el.addEventListener('click', function () { b.value = el.getAttribute('data-pick'); show(); $('viewer').scrollIntoView(); });
  });
  show();
  window.addEventListener('load', function () {
    var loaded = 0, broken = 0;
    Array.prototype.forEach.call(document.images, function (img) {
      if (img.complete && img.naturalWidth > 0) { loaded += 1; } else { broken += 1; }
    });
    body.setAttribute('data-images-loaded', String(loaded));
    body.setAttribute('data-images-broken', String(broken));
  });
})();
)js";

void summary(std::string& h, const json& r) {
  h += "<h2 id=\"summary\">Each method against the exact tracer</h2><p class=\"note\">PSNR on displayed (sRGB, "
       "clamped) values; linear figures on the stored values. The reference is the exact Whitted tracer on the same "
       "triangles, 4 x 8 samples a pixel. Click a heat map below to put it in the viewer.</p>";
  h += "<table><tr><th>method</th><th>PSNR dB</th><th>RMSE (sRGB)</th><th>linear RMSE</th><th>max error /255</th>"
       "<th>at pixel</th><th>&gt; 1/255 %</th><th>&gt; 2/255 %</th><th>&gt; 8/255 %</th><th>time ms</th>"
       "<th>matched tracer rung</th><th>its time ms</th><th>time / matched rung</th></tr>";
  h += "<tr><td>raytrace (reference, 32 samples)</td><td colspan=\"8\"></td>" + figure(r, "reference.total_ms", 0) +
       "<td colspan=\"3\"></td></tr>";
  for (const std::string& m : method_order(r)) {
    const json& x = r["methods"][m];
    const std::string k = "methods." + m;
    if (x.contains("failed")) {
      h += "<tr><td>" + escape(m) +
           "</td><td colspan=\"10\" class=\"fail\">not rendered: " + escape(x["failed"].get<std::string>()) +
           "</td></tr>";
      continue;
    }
    const json& w = x["error"]["worst_pixel"];
    h += "<tr><td>" + escape(m) + "</td>" + figure(r, k + ".error.psnr_db", 2) + figure(r, k + ".error.rmse", 5) +
         figure(r, k + ".error.linear.rmse", 5) + figure(r, k + ".error.max_abs", 1, 255) + "<td>(" +
         std::to_string(w.value("x", 0)) + ", " + std::to_string(w.value("y", 0)) + ") " +
         escape(w.value("channel", std::string("?"))) + "</td>" + figure(r, k + ".error.share_over_1_255", 2, 100) +
         figure(r, k + ".error.share_over_2_255", 2, 100) + figure(r, k + ".error.share_over_8_255", 2, 100) +
         figure(r, k + ".total_ms", 0) + figure(r, k + ".matched_rung.samples", 0) +
         figure(r, k + ".matched_rung.total_ms", 0) + figure(r, k + ".matched_rung.time_ratio", 2) + "</tr>";
  }
  h += "</table><p class=\"note\">The matched rung: the exact tracer at the fewest samples a pixel whose image is at "
       "least as close to the reference as the method's (the ladder below). Time / matched rung above 1: that tracer "
       "was faster at this error.</p>";
}

bool on_front(const json& r, const std::string& name) {
  for (const json& f : r.value("front", json::array())) {
    if (f == name) return true;
  }
  return false;
}

// One sentence a method: what it reached, and the fastest way to that error on this scene.
void verdict(std::string& h, const json& r) {
  h += "<h2 id=\"verdict\">Verdict</h2><p class=\"note\">On this scene, at this size, on this machine. The rival "
       "of each method is the exact tracer at the fewest samples a pixel that reaches the method's error.</p><ul>";
  for (const std::string& m : method_order(r)) {
    const json& x = r["methods"][m];
    const std::string k = "methods." + m;
    if (x.contains("failed")) {
      h += "<li><b>" + escape(m) + "</b>: not rendered.</li>";
      continue;
    }
    const json& rung = x["matched_rung"];
    const double ratio = rung.value("time_ratio", 0.0);
    const std::string samples = rung.value("samples", 0) == 1 ? "1 sample" : rung["samples"].dump() + " samples";
    h += "<li><b>" + escape(m) + "</b>: " + figure(r, k + ".error.psnr_db", 1, 1, "span") + " dB in " +
         figure(r, k + ".total_ms", 0, 1, "span") + " ms. ";
    if (ratio > 1) {
      h += "The exact tracer at " + samples + " a pixel is as close in " +
           figure(r, k + ".matched_rung.total_ms", 0, 1, "span") + " ms: it is faster at this error, by " +
           figure(r, k + ".matched_rung.time_ratio", 2, 1, "span") + "x.";
    } else {
      h += std::string("Faster than the exact tracer at this error: it needs ") + samples + " a pixel (" +
           figure(r, k + ".matched_rung.total_ms", 0, 1, "span") + " ms).";
    }
    if (on_front(r, m)) h += " On the front: nothing here is both faster and closer.";
    h += "</li>";
  }
  h += "</ul>";
}

// The chart of time against error: each method, the tracer's ladder, the Pareto front.
void front_chart(std::string& h, const json& r) {
  Plot p;
  p.title = "Time against error";
  p.x_name = "time, ms (log)";
  p.y_name = "PSNR against the reference, dB";
  p.curve_name = "raytrace at 1 to 16 samples a pixel";
  p.log_x = true;
  p.id = "front-chart";
  for (const std::string& m : method_order(r)) {
    const json& x = r["methods"][m];
    if (x.contains("failed") || !x["error"]["psnr_db"].is_number()) continue;
    p.points.push_back({x.value("total_ms", 0.0), x["error"]["psnr_db"].get<double>()});
    p.labels.push_back(m);
    p.front.push_back(on_front(r, m));
  }
  for (const json& rung : r.value("ladder", json::array())) {
    if (!rung["error"]["psnr_db"].is_number()) continue;  // 32: the reference, exact
    p.curve.push_back({rung.value("total_ms", 0.0), rung["error"]["psnr_db"].get<double>()});
    p.curve_labels.push_back(rung["samples"].dump());
    p.curve_front.push_back(on_front(r, "raytrace " + rung["samples"].dump()));
  }
  h += "<h2 id=\"front\">Speed against error</h2>" + svg(p) +
       "<p class=\"note\">Blue: the methods. Red: the exact tracer at 1 to 16 samples a pixel; at 32 it is the "
       "reference itself, with no error. Green: the front, the renders no other render here beats in both time and "
       "error.</p><table><tr><th>raytrace samples a pixel</th><th>time ms</th><th>PSNR dB</th></tr>";
  const json& ladder = r.value("ladder", json::array());
  for (size_t i = 0; i < ladder.size(); ++i) {
    const std::string k = "ladder." + std::to_string(i);
    const bool exact = !ladder[i]["error"]["psnr_db"].is_number();
    h += "<tr><td>" + ladder[i]["samples"].dump() + "</td>" + figure(r, k + ".total_ms", 0) +
         (exact ? "<td>the reference</td>" : figure(r, k + ".error.psnr_db", 2)) + "</tr>";
  }
  h += "</table>";
}

void viewer(std::string& h, const json& r) {
  std::string options = "<option value=\"images/raytrace.png\">raytrace (reference)</option>";
  for (const std::string& m : method_order(r)) {
    if (r["methods"][m].contains("failed")) continue;
    options += "<option value=\"images/" + escape(m) + ".png\">" + escape(m) + "</option>";
    options += "<option value=\"images/" + escape(m) + ".heat.png\">" + escape(m) + " heat map</option>";
  }
  if (r["crosscheck"].contains("samples_image")) {
    options += "<option value=\"images/crosscheck_samples.png\">crosscheck: samples that differ</option>";
  }
  h +=
      "<h2 id=\"viewer\">Side by side</h2><div class=\"controls\"><label>left <select id=\"pick-a\">" + options +
      "</select></label><label>right <select id=\"pick-b\">" + options +
      "</select></label><button id=\"flip\" type=\"button\">flip</button><label>wipe <input id=\"wipe\" type=\"range\" "
      "min=\"0\" max=\"100\" value=\"50\"></label><label>zoom <select id=\"zoom\"><option>1</option><option>2</option>"
      "<option>4</option><option>8</option></select></label></div><div id=\"view-label\" class=\"note\"></div>"
      "<div class=\"viewer\"><img id=\"view-b\" class=\"px base\" alt=\"right image\" src=\"images/raytrace.png\">"
      "<img id=\"view-a\" class=\"px layer\" alt=\"left image\" src=\"images/raytrace.png\"></div>"
      "<p class=\"note\">The left image covers the right one up to the wipe's line; zoom enlarges pixels as they are "
      "(scroll to move over the image).</p>";
  // Defaults: abuffer's heat map against gpu's, or whatever two there are.
  h += "<script>document.getElementById('pick-b').selectedIndex = Math.min(1, "
       "document.getElementById('pick-b').options.length - 1);</script>";
  h += "<h2 id=\"images\">Images and heat maps</h2><div class=\"gallery\"><figure><img class=\"px\" "
       "src=\"images/raytrace.png\" alt=\"raytrace\"><figcaption>raytrace: the reference</figcaption></figure>";
  for (const std::string& m : method_order(r)) {
    const json& x = r["methods"][m];
    if (x.contains("failed")) continue;
    h += "<figure><img class=\"px\" src=\"images/" + escape(m) + ".png\" alt=\"" + escape(m) + "\"><figcaption>" +
         escape(m) + "</figcaption></figure><figure><img class=\"px\" src=\"images/" + escape(m) +
         ".heat.png\" alt=\"" + escape(m) + " heat map\" data-pick=\"images/" + escape(m) +
         ".heat.png\" style=\"cursor:pointer\"><figcaption>" + escape(m) +
         " against raytrace: black 0, blue 1-2/255, green 8, yellow 32, red 128/255 and above"
         "</figcaption></figure>";
  }
  h += "</div>";
}

void regions(std::string& h, const json& r) {
  h += "<h2 id=\"regions\">Where the error lies</h2><p class=\"note\">Pixels grouped by what the reference sees at "
       "their centre: the kind of surface (by its material) and the object; \"in shadow\": the pixels whose surface "
       "some light does not reach whole, whatever their kind.</p>";
  for (const std::string& m : method_order(r)) {
    const json& x = r["methods"][m];
    if (x.contains("failed")) continue;
    h += "<h3>" + escape(m) +
         "</h3><table><tr><th>surface</th><th>pixels</th><th>PSNR dB</th><th>&gt; 2/255 %</th></tr>";
    for (const auto& [kind, f] : x["regions"]["kinds"].items()) {
      const std::string k = "methods." + m + ".regions.kinds." + kind;
      h += "<tr><td>" + escape(kind) + "</td>" + figure(r, k + ".pixels", 0) + figure(r, k + ".psnr_db", 2) +
           figure(r, k + ".share_over_2_255", 2, 100) + "</tr>";
    }
    h += "</table><table><tr><th>object</th><th>material</th><th>pixels</th><th>RMSE</th><th>&gt; 2/255 %</th></tr>";
    for (const json& o : x["regions"]["objects"]) {
      h += "<tr><td>" + escape(o.value("name", std::string())) + "</td><td>" +
           escape(o.value("material", std::string())) + "</td><td class=\"num\">" +
           std::to_string(o.value("pixels", 0)) + "</td><td class=\"num\">" + fixed(o.value("rmse", 0.0), 5) +
           "</td><td class=\"num\">" + fixed(100 * o.value("share_over_2_255", 0.0), 2) + "</td></tr>";
    }
    h += "</table>";
  }
}

void timing(std::string& h, const json& r) {
  h += "<h2 id=\"time\">Time</h2><p class=\"note\">Milliseconds of each pass, as each render's stats give them "
       "(stats/*.json).</p>";
  std::vector<std::string> passes;
  const auto collect = [&](const json& t) {
    for (const auto& [p, v] : t.items()) {
      if (std::find(passes.begin(), passes.end(), p) == passes.end()) passes.push_back(p);
    }
  };
  collect(r["reference"]["timings_ms"]);
  for (const std::string& m : method_order(r)) {
    if (r["methods"][m].contains("timings_ms")) collect(r["methods"][m]["timings_ms"]);
  }
  h += "<table><tr><th>pass</th><th>raytrace</th>";
  for (const std::string& m : method_order(r)) h += "<th>" + escape(m) + "</th>";
  h += "</tr>";
  for (const std::string& p : passes) {
    h += "<tr><td>" + escape(p) + "</td>" + figure(r, "reference.timings_ms." + p, 1);
    for (const std::string& m : method_order(r)) h += figure(r, "methods." + m + ".timings_ms." + p, 1);
    h += "</tr>";
  }
  h += "</table>";
}

void crosscheck(std::string& h, const json& r) {
  const json& c = r["crosscheck"];
  h += "<h2 id=\"crosscheck\">The GPU against the CPU</h2><p><b>Covers:</b> " + escape(c.value("covers", "")) +
       ".<br><b>Does not cover:</b> " + escape(c.value("does_not_cover", "")) + ".</p>";
  if (c.contains("skipped")) {
    h += "<p class=\"note\">Not run: " + escape(c["skipped"].get<std::string>()) + "</p>";
    return;
  }
  const bool pass = c.value("pass", false);
  h += std::string("<p>Verdict: <span class=\"") + (pass ? "pass\">PASS" : "fail\">FAIL") + "</span> (" +
       escape(c.value("gl", "")) + ")" + (pass ? "" : ": " + escape(c.value("failures", ""))) + "</p>";
  h += "<div class=\"gallery\"><figure><img class=\"px\" src=\"" + escape(c.value("samples_image", "")) +
       "\" alt=\"camera samples where GPU and CPU differ\"><figcaption>Pixels where some of the 32 camera samples see "
       "another object on the GPU than on the CPU, in red (yellow when all do), over the CPU image in grey: " +
       std::to_string(c.value("pixels_with_differing_samples", 0)) + " pixels</figcaption></figure>";
  if (c.contains("shadows_image")) {
    h += "<figure><img class=\"px\" src=\"" + escape(c["shadows_image"].get<std::string>()) +
         "\" alt=\"shadow samples where the GPU's volumes and the tracer differ\"><figcaption>Shadow samples where the "
         "GPU's shadow volumes and the exact tracer differ</figcaption></figure>";
  }
  h += "</div>";
}

// The crosscheck's internal figures, one a row.
void crosscheck_figures(std::string& h, const json& r) {
  const json& c = r["crosscheck"];
  if (c.contains("skipped")) return;
  h += "<h3>The crosscheck's figures</h3><table><tr><th>figure</th><th>value</th></tr>";
  for (const auto& [section, values] : c["result"].items()) {
    if (!values.is_object()) continue;
    for (const auto& [name, v] : values.items()) {
      if (!v.is_number()) continue;
      h += "<tr><td>" + escape(section + " " + name) + "</td>" +
           figure(r, "crosscheck.result." + section + "." + name, v.is_number_integer() ? 0 : 6) + "</tr>";
    }
  }
  h += "</table>";
}

// For abcube's own developers, folded: the sweep over N with the Error_Parallax plot against
// the thesis's bound, and the crosscheck's internal figures.
void developers(std::string& h, const json& r) {
  h += "<h2 id=\"developers\">For abcube's developers</h2><details><summary>The sweep over N, Error_Parallax against "
       "the thesis's bound, the crosscheck's figures</summary>";
  const json& points = r["sweep"]["points"];
  if (!points.empty()) {
    Plot speed;
    speed.title = "abuffer: error against time, one point a cube resolution N";
    speed.x_name = "time, ms";
    speed.y_name = "PSNR against raytrace, dB";
    Plot bound;
    bound.title = "abuffer: Error_Parallax of reflection rays against N";
    bound.x_name = "N (texels a face edge)";
    bound.y_name = "Error_Parallax";
    bound.curve_name = "the thesis's bound 1/(2 N^2)";
    bound.log_y = bound.log_x = true;
    for (const json& p : points) {
      const json& db = p["error"]["psnr_db"];
      speed.points.push_back({p.value("total_ms", 0.0), db.is_number() ? db.get<double>() : 200.0});
      speed.labels.push_back("N " + std::to_string(p.value("n", 0)));
      if (p.contains("error_parallax_mean")) {
        bound.points.push_back({double(p["n"].get<int>()), p["error_parallax_mean"].get<double>()});
        bound.labels.push_back("mean");
        bound.points.push_back({double(p["n"].get<int>()), p["error_parallax_max"].get<double>()});
        bound.labels.push_back("max");
      }
      bound.curve.push_back({double(p["n"].get<int>()), p.value("bound_1_over_2n2", 0.0)});
    }
    h += "<h3>abuffer over N</h3>" + svg(speed);
    if (!bound.points.empty()) h += svg(bound);
    h += "<table><tr><th>N</th><th>time ms</th><th>PSNR dB</th><th>Error_Parallax mean</th><th>max</th>"
         "<th>bound 1/(2N^2)</th><th>within the bound %</th></tr>";
    for (size_t i = 0; i < points.size(); ++i) {
      const std::string k = "sweep.points." + std::to_string(i);
      h += "<tr><td>" + std::to_string(points[i].value("n", 0)) + "</td>" + figure(r, k + ".total_ms", 0) +
           figure(r, k + ".error.psnr_db", 2) + figure(r, k + ".error_parallax_mean", 6) +
           figure(r, k + ".error_parallax_max", 6) + figure(r, k + ".bound_1_over_2n2", 8) +
           figure(r, k + ".error_parallax_within_bound", 2, 100) + "</tr>";
    }
    h += "</table>";
  }
  crosscheck_figures(h, r);
  h += "</details>";
}

void context(std::string& h, const json& r) {
  h += "<h2 id=\"context\">Context</h2><h3>The plan: what was modelled and what was skipped</h3>";
  for (const std::string& m : method_order(r)) {
    const json& x = r["methods"][m];
    if (!x.contains("plan")) continue;
    h += "<p><b>" + escape(m) + "</b>: passes ";
    std::string passes;
    for (const json& p : x["plan"].value("passes", json::array())) passes += (passes.empty() ? "" : ", ") + p.dump();
    h += escape(passes.empty() ? "-" : passes);
    for (const json& s : x["plan"].value("skipped", json::array())) {
      h += "<br>skipped " + escape(s.value("pass", std::string())) + ": " + escape(s.value("why", std::string()));
    }
    h += "</p>";
  }
  const json& c = r["context"];
  h += "<h3>Machine</h3><table>";
  for (const char* k : {"version", "gl_path", "gl_renderer", "cpu", "cores", "memory", "host"}) {
    if (c.contains(k))
      h += std::string("<tr><td>") + k + "</td><td>" +
           escape(c[k].is_string() ? c[k].get<std::string>() : c[k].dump()) + "</td></tr>";
  }
  h += "</table><h3>Scene</h3><table>";
  for (const auto& [k, v] : c["scene"].items())
    h += "<tr><td>" + escape(k) + "</td>" + figure(r, "context.scene." + k, 0) + "</tr>";
  h += "</table><p class=\"note\">Renders took " + fixed(r.value("render_ms", 0.0), 0) + " ms; the report's own work " +
       fixed(r.value("report_ms", 0.0), 0) + " ms.</p>";
}

}  // namespace

std::string report_html(const json& r) {
  std::string h = "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>abcube report: " +
                  escape(r.value("scene", std::string())) + "</title><style>" + STYLE + "</style></head><body>";
  h += "<h1>abcube report: " + escape(r.value("scene", std::string())) + "</h1><p class=\"note\">" +
       std::to_string(r["size"].value("width", 0)) + " x " + std::to_string(r["size"].value("height", 0)) +
       " pixels; figures in report.json, each render's stats in stats/. <a href=\"#verdict\">verdict</a> | <a "
       "href=\"#summary\">summary</a> | <a href=\"#front\">speed against error</a> | <a "
       "href=\"#viewer\">side by side</a> | <a href=\"#regions\">where</a> | <a href=\"#time\">time</a> | <a "
       "href=\"#crosscheck\">GPU against CPU</a> | <a href=\"#context\">context</a> | <a href=\"#developers\">for "
       "developers</a></p>";
  verdict(h, r);
  summary(h, r);
  front_chart(h, r);
  viewer(h, r);
  regions(h, r);
  timing(h, r);
  crosscheck(h, r);
  context(h, r);
  developers(h, r);
  return h + "<script>" + SCRIPT + "</script></body></html>\n";
}

}  // namespace abcube
