// The camera's fragments shaded by a MapShader and resolved (render_with_map, header):
// each fragment at its covered quarters, adaptively, and the shadow edges' second pass.
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <utility>
#include <vector>

#include "base/samples.hpp"
#include "io/image_io.hpp"
#include "raster/abuffer.hpp"
#include "raster/raster.hpp"
#include "search/deferred_searches.hpp"
#include "search/search.hpp"
#include "scene/texture.hpp"
#include "shading/fragment_texture.hpp"
#include "shading/map_shading.hpp"
#include "shading/pass_rows.hpp"
#include "shading/resolve.hpp"
#include "shading/secondary_edges.hpp"
#include "shading/shadow_edges.hpp"

namespace abcube {

namespace {

// The quarters of the 4x8 mask (samples.hpp): columns 0-3 / 4-7 of rows 0-1 / 2-3.
constexpr CoverageMask QUARTERS[4] = {0x00000f0fu, 0x0000f0f0u, 0x0f0f0000u, 0xf0f00000u};

// Is the sRGB-encoded difference of two colours above `threshold` in any channel?
bool differ(const glm::dvec3& a, const glm::dvec3& b, double threshold = QUARTER_SPLIT_SRGB) {
  for (int k = 0; k < 3; ++k) {
    const double ea = srgb_encode(static_cast<float>(std::clamp(a[k], 0.0, 1.0)));
    const double eb = srgb_encode(static_cast<float>(std::clamp(b[k], 0.0, 1.0)));
    if (std::fabs(ea - eb) > threshold) return true;
  }
  return false;
}

// Do any two of the `count` colours differ (above)?
bool any_differ(const glm::dvec3* colour, int count) {
  for (int a = 0; a < count; ++a) {
    for (int b = a + 1; b < count; ++b) {
      if (differ(colour[a], colour[b])) return true;
    }
  }
  return false;
}

// Did the secondary rays of the `count` points find different surfaces (PrimaryLights::trail)?
bool trails_differ(const PrimaryLights* direct, int count) {
  for (int k = 1; k < count; ++k) {
    if (direct[k].trail != direct[0].trail) return true;
  }
  return false;
}

// Secondary searches and those of them that found nothing (the "fallback" AOV, header).
std::pair<uint64_t, uint64_t> searches_and_failures(const MapShadingStats& s) {
  const SearchStats& q = s.searches;
  const uint64_t rays =
      q.reflection.rays + q.refraction_exit.rays + q.shadow.rays + s.lens_transfers + s.lens_fallbacks;
  const uint64_t failed =
      q.reflection.misses + q.refraction_exit.misses + q.shadow.zero_area + q.shadow.aborted + s.lens_fallbacks;
  return {rays, failed};
}

// A fragment's covered quarters: their centroids on its triangle's plane, their shares of
// its coverage, their masks.
struct Quarters {
  glm::dvec3 point[4];
  double weight[4];
  CoverageMask mask[4];
  int count = 0;
};

// a += (after - before), for the searches taken (not the stand-ins).
void add_taken(DeferredTally* a, const DeferredTally& before, const DeferredTally& after) {
  a->used += after.used - before.used;
  a->walked_now += after.walked_now - before.walked_now;
}

// One render_with_map call: its inputs, the per-worker statistics and light records, and
// what the shadow and secondary edges' passes share.
class MapRender {
 public:
  MapRender(const SceneData& scene, const ABuffer& camera, const MapShader& shader, Image* fallback,
            const std::vector<uint8_t>* only, const std::function<void(double)>* progress,
            FirstStageRows* rows = nullptr)
      : rows_(rows),
        progress_(progress),
        scene_(scene),
        camera_(camera),
        shader_(shader),
        fallback_(fallback),
        only_(only),
        pixels_(static_cast<size_t>(camera.width()) * static_cast<size_t>(camera.height())) {
    if (fallback_) pixel_searches_.assign(pixels_, {0, 0});
    // The plan holds shadow edges only with the quarters (shading_plan.hpp).
    edges_ = shader.shadow_edges() &&
             std::any_of(scene.lights.begin(), scene.lights.end(), [](const PointLight& l) { return l.cast_shadows; });
    if (edges_) {
      seen_.lit.assign(pixels_, 0);
      seen_.dark.assign(pixels_, 0);
      seen_.sides.assign(pixels_, 0);
    }
    sparse_ = shader.quarters_at_edges();  // one point first, then the quarters where neighbours differ
    trails_on_ = shader.secondary_edges() && !shader.one_point() && scene.render.max_depth > 0 &&
                 std::any_of(scene.materials.begin(), scene.materials.end(),
                             [](const Material& m) { return m.reflect > 0.0 || m.transmit > 0.0; });
  }

  // The first stage over the rows `rows_` marks to redo (all in its first pass), the others
  // as `rows_` kept them; then kept for the next pass. Each row shaded is marked again by
  // whether it took a stand-in.
  Image first_stage_kept(const WorkerPixelShader& shade, ResolveOptions ro) {
    const int width = camera_.width(), height = camera_.height();
    FirstStageRows& k = *rows_;
    if (!k.kept) {
      k.rows.size(static_cast<size_t>(height));
    } else {
      if (edges_) seen_ = k.seen, seen_.forget_rows(k.rows.redo, width);
      if (trails_on_) trails_ = k.trails, trails_.forget_rows(k.rows.redo, width);
      if (fallback_) pixel_searches_ = k.pixel_searches;
    }
    std::vector<uint8_t> mask(pixels_, 0);
    for (size_t p = 0; p < pixels_; ++p) {
      const size_t y = p / static_cast<size_t>(width);
      if (!k.rows.redo[y]) continue;
      mask[p] = ro.only ? (*ro.only)[p] : 1;
      if (fallback_) pixel_searches_[p] = {0, 0};
    }
    const std::vector<uint8_t> redo = k.rows.redo;
    for (size_t y = 0; y < redo.size(); ++y) {
      if (!redo[y]) continue;
      k.rows.start_row(y);
      ++k.rows.rows_shaded;
    }
    ro.only = &mask;
    stage_ = &k.rows;
    Image image = resolve_image_per_worker(camera_, *scene_.triangles, shade, scene_.background, ro);
    if (k.kept) {
      const size_t row = static_cast<size_t>(width) * static_cast<size_t>(image.channels);
      for (size_t y = 0; y < redo.size(); ++y) {
        if (redo[y]) continue;
        std::copy_n(k.image.data.begin() + static_cast<std::ptrdiff_t>(y * row), row,
                    image.data.begin() + static_cast<std::ptrdiff_t>(y * row));
      }
    }
    k.kept = true;
    k.image = image;
    if (edges_) k.seen = seen_;
    if (trails_on_) k.trails = trails_;
    if (fallback_) k.pixel_searches = pixel_searches_;
    return image;
  }

  Image render(int threads, bool neighbours, MapShadingStats* stats) {
    ResolveOptions ro;
    ro.threads = threads;
    ro.exact_priority = shader_.exact_priority();
    ro.only = only_;
    ro.plan = shader_.resolve_plan();
    if (progress_ && *progress_) ro.progress = *progress_;  // the first pass: most of the shading
    // SHADOW EDGES and SECONDARY EDGES (header): what each pixel's points saw, and in the
    // second pass the pixels an edge runs between whose points and their neighbour's.
    if ((edges_ || trails_on_ || sparse_) && only_ && neighbours) {
      widened_ = with_neighbours(*only_, camera_.width(), camera_.height());
      ro.only = &widened_;
    }
    // Statistics per resolve worker, merged at the end: no lock while shading. The records
    // of the points' lights too, reused fragment after fragment (their vectors keep their room).
    const size_t workers = static_cast<size_t>(resolve_workers(camera_, ro));
    per_worker_.assign(workers, MapShadingStats{});
    known_.assign(workers, Known{});
    worker_direct_.resize(workers);
    if (trails_on_) trails_ = PixelTrails(pixels_, workers);
    const WorkerPixelShader shade = [this](const Fragment& f, int x, int y, int worker) {
      return shade_fragment(f, x, y, worker);
    };
    Image image = rows_ ? first_stage_kept(shade, ro)
                        : resolve_image_per_worker(camera_, *scene_.triangles, shade, scene_.background, ro);
    if (edges_ || trails_on_) second_pass(shade, ro, &image);
    if (sparse_) sparse_pass(shade, ro, &image);
    stage_ = nullptr;
    if (rows_) {
      DeferredTally& took = rows_->image_took;
      took = DeferredTally{};
      for (const RowRecords* r : {&rows_->rows, &rows_->edges.rows, &rows_->sparse.rows}) {
        for (const DeferredTally& t : r->took) add_taken(&took, DeferredTally{}, t);
        if (stats) {
          for (const MapShadingStats& s : r->stats) stats->merge(s);
        }
      }
    }
    if (stats) {
      for (const MapShadingStats& s : per_worker_) stats->merge(s);
    }
    if (fallback_) {
      *fallback_ = Image(camera_.width(), camera_.height(), 1, 0.f);
      for (size_t k = 0; k < pixel_searches_.size(); ++k) {
        const auto [rays, failed] = pixel_searches_[k];
        if (rays > 0) fallback_->data[k] = static_cast<float>(static_cast<double>(failed) / static_cast<double>(rays));
      }
    }
    return image;
  }

 private:
  // The fragment shaded at its covered quarters, adaptively (header, QUARTER_SPLIT_SRGB).
  ShadedFragment shade_fragment(const Fragment& f, int x, int y, int worker) {
    // DEFERRED SEARCHES: the stage's statistics by row, and whether the row took a stand-in
    // (pass_rows.hpp).
    RowRecords* const by_row = stage_;
    const size_t row = static_cast<size_t>(y);
    MapShadingStats* s = by_row ? &by_row->stats[row] : &per_worker_[static_cast<size_t>(worker)];
    const DeferredTally tally = by_row ? DeferredSearches::tally_here() : DeferredTally{};
    Known& known = known_[static_cast<size_t>(worker)];
    if (known.row != y) {  // KNOWN BLOCKERS (map_shading.hpp): none carried from another row
      known.row = y;
      known.blockers.clear();
    }
    const size_t at = static_cast<size_t>(y) * static_cast<size_t>(camera_.width()) + static_cast<size_t>(x);
    const std::pair<uint64_t, uint64_t> before =
        fallback_ ? searches_and_failures(*s) : std::pair<uint64_t, uint64_t>{};
    glm::dvec3 c;
    // SPARSE (header): one point, the quarters in the sparse pass.
    if (shader_.one_point() && !sparse_again_) {
      c = shade_at(f, x, y, fragment_point(camera_, *scene_.triangles, f, x, y), f.mask, nullptr, s, &known.blockers);
    } else {
      c = shade_quarters(f, x, y, at, worker, s, &known.blockers);
    }
    if (fallback_) {
      const std::pair<uint64_t, uint64_t> after = searches_and_failures(*s);
      auto& p = pixel_searches_[at];
      p.first += after.first - before.first;
      p.second += after.second - before.second;
    }
    if (by_row) {
      const DeferredTally now = DeferredSearches::tally_here();
      add_taken(&by_row->took[row], tally, now);
      if (now.stand_ins != tally.stand_ins) by_row->redo[row] = 1;
    }
    return ShadedFragment{c, scene_.materials[scene_.triangles->material_id[f.triangle()]].opacity};
  }

  // The surface the eye ray through a point of the fragment's plane really crosses: the
  // point moved onto the mesh (a merged fragment keeps one triangle of several: abuffer.hpp
  // MERGE).
  SurfacePoint surface_at(const Fragment& f, int x, int y, const glm::dvec3& p) const {
    if (!shader_.refines_on_mesh()) return surface_point(scene_, f.triangle(), p);
    const glm::dvec3 eye = scene_.camera.position;
    // One pixel's width seen from the eye, in radians (the mesh refinement's radius).
    const double pixel = glm::length(glm::normalize(camera_.view.direction(x + 1.5, y + 0.5)) -
                                     glm::normalize(camera_.view.direction(x + 0.5, y + 0.5)));
    const glm::dvec3 dir = glm::normalize(p - eye);
    uint32_t tri = f.triangle();
    glm::dvec3 on = p;
    double l = 0;
    const double dist = glm::length(p - eye);
    if (mesh_crossing(shader_.context(), eye, dir, f.triangle(), dist, dist * pixel, &tri, &l)) on = eye + l * dir;
    return surface_point(scene_, tri, on);
  }

  // The colour at point p of the fragment's plane, standing for the covered samples `mask`:
  // a textured surface takes its base colour averaged over those samples, as the exact
  // tracer's 32 rays a pixel see it; the light, shadows and secondary rays are the point's.
  glm::dvec3 shade_at(const Fragment& f, int x, int y, const glm::dvec3& p, CoverageMask mask, PrimaryLights* direct,
                      MapShadingStats* s, KnownBlockers* known) const {
    const glm::dvec3 eye = scene_.camera.position;
    SurfacePoint sp = surface_at(f, x, y, p);
    if (shader_.texture_samples() && sp.material == scene_.triangles->material_id[f.triangle()]) {
      sp.diffuse_given = mean_diffuse_color(scene_, camera_.view, f.triangle(), x, y, mask, &sp.diffuse);
    }
    return shader_.shade(sp, glm::normalize(p - eye), 0, true, s, direct, known);
  }

  Quarters quarters(const Fragment& f, int x, int y) const {
    Quarters q;
    const double total = mask_count(f.mask);
    for (CoverageMask quarter : QUARTERS) {
      const CoverageMask m = f.mask & quarter;
      if (!m) continue;
      const glm::dvec2 c = mask_centroid(m);
      q.point[q.count] = point_on_triangle_plane(camera_.view, *scene_.triangles, f.triangle(), x + c.x, y + c.y);
      q.weight[q.count] = mask_count(m) / total;
      q.mask[q.count] = m;
      ++q.count;
    }
    return q;
  }

  // The fragment's two end quarters shaded, the ones between too where the ends differ (or
  // a shadow edge is forced), each quarter's samples searched again along a shadow's edge.
  glm::dvec3 shade_quarters(const Fragment& f, int x, int y, size_t at, int worker, MapShadingStats* s,
                            KnownBlockers* known) {
    const uint64_t force = forced_.empty() ? 0 : forced_[at];
    const bool force_secondary = !forced_secondary_.empty() && forced_secondary_[at];
    const std::function<glm::dvec3(const glm::dvec3&)> on_surface = [&](const glm::dvec3& p) {
      return surface_at(f, x, y, p).point;
    };
    const Quarters q = quarters(f, x, y);
    PrimaryLights* const direct = worker_direct_[static_cast<size_t>(worker)].data();
    const bool secondary = secondary_edges(f);
    // What the points' lights gave (SHADOW EDGES) and their secondary rays found (SECONDARY EDGES).
    PrimaryLights* const record = edges_ || secondary ? direct : nullptr;
    if (q.count <= 1) {
      glm::dvec3 c = shade_at(f, x, y, fragment_point(camera_, *scene_.triangles, f, x, y), f.mask, record, s, known);
      if (secondary && force_secondary) {
        ++s->secondary_edge_fragments;
        c += secondary_samples(f, x, y, f.mask, s, known) - direct[0].secondary;
      }
      if (secondary && !trails_.empty()) trails_.note_point(at, direct[0].trail);
      if (edges_ && force) {
        refine_shadow_edges(scene_, camera_, f, x, y, q.mask, 1, direct, force, &c, on_surface, shader_, s, known,
                            &seen_.sides[at]);
      }
      if (edges_) seen_.note(at, scene_, direct, 1, true);
      return c;
    }
    ++s->multi_point_fragments;
    const int last = q.count - 1;
    glm::dvec3 colour[4];
    colour[0] = shade_at(f, x, y, q.point[0], q.mask[0], record ? &direct[0] : nullptr, s, known);
    colour[last] = shade_at(f, x, y, q.point[last], q.mask[last], record ? &direct[last] : nullptr, s, known);
    const bool ends_differ = edges_ && direct[0].shadow != direct[last].shadow;
    // A texture may differ between quarters whose ends agree: each of them is shaded with
    // its own samples' base colour (--texture-lookups samples). A mirror's or glass's quarters
    // are all shaded, so that SECONDARY EDGES compares them all.
    const bool split = force != 0 || ends_differ || differ(colour[0], colour[last]) || textured(f) || secondary;
    for (int k = 1; k < last; ++k) {
      colour[k] = split ? shade_at(f, x, y, q.point[k], q.mask[k], record ? &direct[k] : nullptr, s, known)
                        : 0.5 * (colour[0] + colour[last]);
    }
    const bool refined =
        secondary && (force_secondary || (trails_differ(direct, q.count) && any_differ(colour, q.count)));
    if (secondary && !refined && !trails_.empty()) {
      for (int k = 0; k < q.count; ++k) trails_.note_point(at, direct[k].trail);
    }
    if (refined) {
      // SECONDARY EDGES (map_shading.hpp): each quarter's kr and kt terms the mean of its
      // samples', each searched from its own point; the trails its samples found on each side
      // of the pixel noted.
      SideTrails sides;
      for (int k = 0; k < q.count; ++k) {
        colour[k] += secondary_samples(f, x, y, q.mask[k], s, known, &sides) - direct[k].secondary;
      }
      ++s->secondary_edge_fragments;
      if (!trails_.empty()) {
        trails_.note_several(at);
        trails_.note_sides(at, worker, sides);
      }
    }
    if (edges_ && split) {
      refine_shadow_edges(scene_, camera_, f, x, y, q.mask, q.count, direct, force, colour, on_surface, shader_, s,
                          known, &seen_.sides[at]);
    }
    if (edges_) seen_.note(at, scene_, direct, q.count, split);
    glm::dvec3 c = q.weight[0] * colour[0] + q.weight[last] * colour[last];
    for (int k = 1; k < last; ++k) c += q.weight[k] * colour[k];
    return c;
  }

  // Whether fragment f is refined by SECONDARY EDGES: a material with a reflection or
  // transmission term, bounces left, --secondary-edges samples.
  bool secondary_edges(const Fragment& f) const {
    const Material& m = scene_.materials[scene_.triangles->material_id[f.triangle()]];
    return shader_.secondary_edges() && scene_.render.max_depth > 0 && (m.reflect > 0.0 || m.transmit > 0.0);
  }

  // The mean of the kr and kt terms of the covered samples `mask` of fragment f, each
  // searched from its own point of the fragment's plane (moved onto the mesh as the shading
  // points are); `sides` (optional) gains the trails of the samples on each side of the pixel.
  glm::dvec3 secondary_samples(const Fragment& f, int x, int y, CoverageMask mask, MapShadingStats* s,
                               KnownBlockers* known, SideTrails* sides = nullptr) const {
    glm::dvec3 sum(0.0);
    for (CoverageMask m = mask; m; m &= m - 1) {
      const int b = __builtin_ctz(m);
      const glm::dvec3 p =
          point_on_triangle_plane(camera_.view, *scene_.triangles, f.triangle(), x + sample_dx(b), y + sample_dy(b));
      uint64_t trail = 0;
      sum += shader_.secondary(surface_at(f, x, y, p), glm::normalize(p - scene_.camera.position), s, &trail, known);
      ++s->secondary_edge_samples;
      for (int side = 0; sides && side < 4; ++side) {
        if (sample_sides(b) & (1 << side)) (*sides)[static_cast<size_t>(side)].add(trail);
      }
    }
    return sum / double(mask_count(mask));
  }

  // Whether fragment f's base colour is averaged over its samples: a textured material, with
  // --texture-lookups samples.
  bool textured(const Fragment& f) const {
    return shader_.texture_samples() && scene_.textures &&
           scene_.textures->image_of(scene_.triangles->material_id[f.triangle()]) >= 0;
  }

  // The second pass: the pixels an edge runs beside, shaded again with those lights' samples
  // searched, or their secondary fragments shaded at their samples; their searches are
  // counted once more, as they were made.
  void second_pass(const WorkerPixelShader& shade, const ResolveOptions& ro, Image* image) {
    if (edges_) forced_ = seen_.across(camera_.width(), camera_.height(), only_);
    if (trails_on_) forced_secondary_ = trails_.across(camera_.width(), camera_.height(), only_);
    std::vector<uint8_t> again(pixels_, 0);
    uint64_t flagged = 0, flagged_secondary = 0;
    for (size_t p = 0; p < pixels_; ++p) {
      const bool light = !forced_.empty() && forced_[p], secondary = !forced_secondary_.empty() && forced_secondary_[p];
      if (!light && !secondary) continue;
      again[p] = 1;
      flagged += light ? 1 : 0;
      flagged_secondary += secondary ? 1 : 0;
    }
    shade_again(shade, ro, again, flagged + flagged_secondary, image, rows_ ? &rows_->edges : nullptr);
    per_worker_[0].shadow_edge_pixels += flagged;
    per_worker_[0].secondary_edge_pixels += flagged_secondary;
  }

  // SPARSE (map_shading.hpp): the pixels whose colour differs from a 4-neighbour's by more
  // than SPARSE_SPLIT_SRGB, shaded again at their quarters.
  void sparse_pass(const WorkerPixelShader& shade, const ResolveOptions& ro, Image* image) {
    const int width = camera_.width(), height = camera_.height();
    const size_t channels = static_cast<size_t>(image->channels);
    const auto colour = [&](size_t p) {
      const float* c = image->data.data() + p * channels;
      return glm::dvec3(c[0], c[1], c[2]);
    };
    const auto apart = [&](const glm::dvec3& c, size_t q) { return differ(c, colour(q), SPARSE_SPLIT_SRGB); };
    std::vector<uint8_t> again(pixels_, 0);
    uint64_t flagged = 0;
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const size_t p = static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
        if (only_ && !(*only_)[p]) continue;
        const glm::dvec3 c = colour(p);
        const size_t row = static_cast<size_t>(width);
        if ((x > 0 && apart(c, p - 1)) || (x + 1 < width && apart(c, p + 1)) || (y > 0 && apart(c, p - row)) ||
            (y + 1 < height && apart(c, p + row))) {
          again[p] = 1;
          ++flagged;
        }
      }
    }
    sparse_again_ = true;  // shade_fragment: the quarters
    shade_again(shade, ro, again, flagged, image, rows_ ? &rows_->sparse : nullptr);
    sparse_again_ = false;
    per_worker_[0].sparse_pixels += flagged;
  }

  // The pixels `again` (`count` of them) resolved once more, their searches counted afresh;
  // the neighbours a pass shaded beside `only` (widened_) black again, as `only` says.
  // DEFERRED SEARCHES: `kept` (null: none) the stage as the last pass left it; its rows whose
  // pixels need no shading again (StageRows::rows_to_shade) take their kept colours.
  void shade_again(const WorkerPixelShader& shade, const ResolveOptions& ro, const std::vector<uint8_t>& again,
                   uint64_t count, Image* image, StageRows* kept) {
    const size_t channels = static_cast<size_t>(image->channels), width = static_cast<size_t>(camera_.width());
    for (size_t p = 0; p < pixels_; ++p) {
      const bool outside = !widened_.empty() && !(*only_)[p];
      if (outside) std::fill_n(image->data.begin() + static_cast<std::ptrdiff_t>(p * channels), image->channels, 0.f);
      if (fallback_ && (outside || again[p])) pixel_searches_[p] = {0, 0};
    }
    std::vector<uint8_t> shaded = again, rows;
    if (kept) {
      rows = kept->rows_to_shade(camera_.width(), camera_.height(), again, forced_, forced_secondary_);
      if (!kept->kept) kept->rows.size(rows.size());
      count = 0;
      for (size_t y = 0; y < rows.size(); ++y) {
        if (!rows[y]) continue;
        kept->rows.start_row(y);
        const auto first = shaded.begin() + static_cast<std::ptrdiff_t>(y * width);
        const uint64_t in_row = static_cast<uint64_t>(std::count(first, first + static_cast<std::ptrdiff_t>(width), 1));
        kept->rows.rows_shaded += in_row > 0 ? 1 : 0;
        count += in_row;
      }
      for (size_t p = 0; p < pixels_; ++p) shaded[p] = rows[p / width] ? shaded[p] : 0;
      stage_ = &kept->rows;
    }
    if (count > 0) {
      for (Known& k : known_) k.row = -1;  // each row starts afresh in this pass too
      ResolveOptions second = ro;
      second.only = &shaded;
      const Image redone = resolve_image_per_worker(camera_, *scene_.triangles, shade, scene_.background, second);
      for (size_t p = 0; p < pixels_; ++p) {
        if (!shaded[p]) continue;
        for (size_t ch = 0; ch < channels; ++ch) image->data[p * channels + ch] = redone.data[p * channels + ch];
      }
    }
    if (!kept) return;
    for (size_t p = 0; p < pixels_ && kept->kept; ++p) {
      if (!again[p] || rows[p / width]) continue;
      std::copy_n(kept->image.data.begin() + static_cast<std::ptrdiff_t>(p * channels), channels,
                  image->data.begin() + static_cast<std::ptrdiff_t>(p * channels));
      if (fallback_) pixel_searches_[p] = kept->pixel_searches[p];
    }
    kept->kept = true;
    kept->again = again, kept->forced = forced_, kept->forced_secondary = forced_secondary_;
    kept->image = *image;
    if (fallback_) kept->pixel_searches = pixel_searches_;
  }

  FirstStageRows* const rows_;                   // DEFERRED SEARCHES: the stages kept between passes
  RowRecords* stage_ = nullptr;                  // the current stage's records by row, when kept
  const std::function<void(double)>* progress_;  // the first pass's rows, when given
  const SceneData& scene_;
  const ABuffer& camera_;
  const MapShader& shader_;
  Image* const fallback_;
  const std::vector<uint8_t>* const only_;
  const size_t pixels_;
  bool edges_ = false;
  bool sparse_ = false;        // --shading-points sparse
  bool sparse_again_ = false;  // in its pass: the quarters
  // Per pixel: secondary searches and failures (one resolve worker owns a row at a time).
  std::vector<std::pair<uint64_t, uint64_t>> pixel_searches_;
  PixelShadows seen_;
  std::vector<uint8_t> widened_;
  std::vector<uint64_t> forced_;  // per pixel, the lights whose edge the second pass searches
  std::vector<MapShadingStats> per_worker_;
  // Per worker: its KNOWN BLOCKERS (map_shading.hpp) and the row they were found in.
  struct Known {
    int row = -1;
    KnownBlockers blockers;
  };
  std::vector<Known> known_;
  std::vector<std::array<PrimaryLights, 4>> worker_direct_;
  bool trails_on_ = false;
  PixelTrails trails_;
  std::vector<uint8_t> forced_secondary_;  // per pixel, 1: its secondary fragments shaded at their samples
};

}  // namespace

Image render_with_map(const SceneData& scene, const ABuffer& camera, const MapShader& shader, int threads,
                      MapShadingStats* stats, Image* fallback, const std::vector<uint8_t>* only, bool neighbours,
                      const std::function<void(double)>* progress) {
  DeferredSearches* deferred = shader.deferred();
  if (!deferred) return MapRender(scene, camera, shader, fallback, only, progress).render(threads, neighbours, stats);
  // DEFERRED SEARCHES: the passes run until one asks nothing new; only its image and its
  // figures stand. Each pass's first stage shades only the rows that took a stand-in in the
  // last (FirstStageRows).
  FirstStageRows rows;
  for (;;) {
    deferred->begin_pass();
    MapShadingStats pass;
    Image image = MapRender(scene, camera, shader, fallback, only, progress, &rows).render(threads, neighbours, &pass);
    if (deferred->queued() == 0) {
      if (stats) stats->merge(pass);
      deferred->note_image(rows.image_took.used, rows.image_took.walked_now, rows.rows.rows_shaded,
                           rows.edges.rows.rows_shaded + rows.sparse.rows.rows_shaded);
      return image;
    }
    deferred->answer_queued();
  }
}

}  // namespace abcube
