#include "raster/abuffer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "raster/cube_map.hpp"
#include "base/error.hpp"
#include "base/normal_encoding.hpp"
#include "reference/triangle_test.hpp"
#include "scene/tie_rule.hpp"
#include "base/memory.hpp"
#include "base/timer.hpp"
#include "scene/scene_load.hpp"
#include "base/parallel.hpp"

namespace abcube {

namespace {

constexpr int BAND_ROWS = 32;
constexpr uint64_t MIB = 1024 * 1024;

// A visible triangle of one view and the pixel rows it may cover.
struct BinEntry {
  uint32_t triangle;
  int y0, y1;
};

// One raster being built.
struct ViewBuild {
  RasterView view;
  std::vector<BinEntry> bins;
  std::vector<uint32_t> offsets;  // counts, then prefix sums
  std::vector<uint32_t> cursor;   // fill position, then kept count per pixel
  std::vector<Fragment> fragments;
  uint64_t triangle_views = 0, clipped = 0, degenerate = 0, edge_on = 0;
};

struct Band {
  size_t view;
  int y0, y1;
};

// Per band results of the fill, summed in band order.
struct BandResult {
  uint64_t dropped = 0, max_list = 0;
};

// Distances (>= 0) to float, rounded outward. For a positive float the next float below
// or above is one step of its bit pattern.
float step_bits(float f, int step) {
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  bits = static_cast<uint32_t>(static_cast<int64_t>(bits) + step);
  std::memcpy(&f, &bits, sizeof bits);
  return f;
}
float round_down(double z) {
  const float f = static_cast<float>(z);
  return static_cast<double>(f) > z && f > 0.0f ? step_bits(f, -1) : f;
}
float round_up(double z) {
  const float f = static_cast<float>(z);
  return static_cast<double>(f) < z ? step_bits(f, +1) : f;
}

// `views` (optional, one byte a triangle): bit `view_bit` clear where the view is known to
// cover none of the triangle's samples (cube_faces_of), which is then culled unset up.
// Degenerate and edge-on triangles keep every bit, so that each view counts them.
void bin_view(const TriangleSoup& soup, const uint8_t* views, int view_bit, ViewBuild* vb) {
  TriangleSetup s;
  const uint32_t count = static_cast<uint32_t>(soup.triangle_count());
  for (uint32_t t = 0; t < count; ++t) {
    if (views && !((views[t] >> view_bit) & 1u)) continue;
    switch (setup_triangle(vb->view, soup, t, &s)) {
      case SetupResult::visible:
        vb->bins.push_back({t, s.y0, s.y1});
        ++vb->triangle_views;
        vb->clipped += s.near_clipped() ? 1 : 0;
        break;
      case SetupResult::degenerate: ++vb->degenerate; break;
      case SetupResult::edge_on: ++vb->edge_on; break;
      case SetupResult::culled: break;
    }
  }
}

// Calls visit(setup) for every triangle binned to the view whose rows meet the band.
template <class Visit>
void for_band_triangles(const TriangleSoup& soup, const ViewBuild& vb, const Band& band, Visit&& visit) {
  TriangleSetup s;
  for (const BinEntry& b : vb.bins) {
    if (b.y1 <= band.y0 || b.y0 >= band.y1) continue;
    if (setup_triangle(vb.view, soup, b.triangle, &s) == SetupResult::visible) visit(s);
  }
}

void count_band(const TriangleSoup& soup, ViewBuild* vb, const Band& band) {
  const size_t w = static_cast<size_t>(vb->view.width);
  uint32_t* counts = vb->offsets.data() + 1;  // pixel p counts into offsets[p + 1]
  for_band_triangles(soup, *vb, band, [&](const TriangleSetup& s) {
    rasterize_rows(s, band.y0, band.y1,
                   [&](int x, int y, CoverageMask) { ++counts[static_cast<size_t>(y) * w + static_cast<size_t>(x)]; });
  });
}

bool before(const Fragment& a, const Fragment& b) {
  return a.zmin < b.zmin || (a.zmin == b.zmin && a.triangle_and_facing < b.triangle_and_facing);
}

// Thesis 5.2.1 merge (docs/design/abuffer-lists.md, "MERGE"): same object, material and
// facing, z ranges overlapping, masks disjoint; and, our addition, no crease between them.
bool mergeable(const TriangleSoup& soup, const Fragment& a, const Fragment& b) {
  const uint32_t ta = a.triangle(), tb = b.triangle();
  return a.back_face() == b.back_face() && (a.mask & b.mask) == 0 && b.zmin <= a.zmax && a.zmin <= b.zmax &&
         soup.object_id[ta] == soup.object_id[tb] && soup.material_id[ta] == soup.material_id[tb] &&
         glm::dot(a.shading_normal(), b.shading_normal()) >= MERGE_MIN_NORMAL_COS;
}

void merge_into(Fragment* into, const Fragment& f) {
  // Area-weighted normal (thesis 5.2.1: C = C1 A1 + C2 A2), areas from the masks.
  const double a1 = mask_count(into->mask), a2 = mask_count(f.mask);
  const glm::dvec3 n = a1 * into->shading_normal() + a2 * f.shading_normal();
  const double len = glm::length(n);
  if (len > 0.0) into->normal = encode_octahedral(n / len);
  // The kept triangle (the fragment's plane) is the one under the pixel centre when only
  // one of them covers a centre sample, so centre look-ups (nearest_layer, the pixel-centre
  // shading point) use the right plane; else the one covering more samples.
  const int c1 = mask_count(into->mask & CENTRE_SAMPLES), c2 = mask_count(f.mask & CENTRE_SAMPLES);
  const bool take = c2 != c1 ? c2 > c1 : a2 > a1 || (a2 == a1 && f.triangle_and_facing < into->triangle_and_facing);
  if (take) into->triangle_and_facing = f.triangle_and_facing;
  into->mask |= f.mask;
  into->zmin = std::min(into->zmin, f.zmin);
  into->zmax = std::max(into->zmax, f.zmax);
}

// finish_fragment_list, with the band's figures.
uint32_t finish_list(const TriangleSoup& soup, const ABufferOptions& options, Fragment* list, uint32_t count,
                     BandResult* r) {
  const uint32_t kept = finish_fragment_list(soup, options, list, count, &r->dropped);
  r->max_list = std::max<uint64_t>(r->max_list, kept);
  return kept;
}

BandResult fill_band(const TriangleSoup& soup, const ABufferOptions& options, ViewBuild* vb, const Band& band) {
  const size_t w = static_cast<size_t>(vb->view.width);
  const size_t p0 = static_cast<size_t>(band.y0) * w, p1 = static_cast<size_t>(band.y1) * w;
  for (size_t p = p0; p < p1; ++p) vb->cursor[p] = vb->offsets[p];
  Fragment* frags = vb->fragments.data();
  for_band_triangles(soup, *vb, band, [&](const TriangleSetup& s) {
    const uint32_t id = s.triangle | (s.back_face() ? Fragment::BACK_FACE_BIT : 0u);
    rasterize_rows(s, band.y0, band.y1, [&](int x, int y, CoverageMask mask) {
      const size_t p = static_cast<size_t>(y) * w + static_cast<size_t>(x);
      ABCUBE_CHECK(vb->cursor[p] < vb->offsets[p + 1], "fill pass covers more than the count pass");
      const FragmentGeometry g = fragment_geometry(vb->view, s, x, y, mask);
      frags[vb->cursor[p]++] = {round_down(g.zmin), round_up(g.zmax), mask, id, encode_octahedral(g.normal)};
    });
  });
  BandResult r;
  for (size_t p = p0; p < p1; ++p) {
    ABCUBE_CHECK(vb->cursor[p] == vb->offsets[p + 1], "fill pass covers less than the count pass");
    vb->cursor[p] = finish_list(soup, options, frags + vb->offsets[p], vb->offsets[p + 1] - vb->offsets[p], &r);
  }
  return r;
}

// Moves the kept part of every list to the front: final offsets, no gaps.
// Closes the gaps the merges left, and hands back what the build alone used: the bins,
// the cursors, and the raw fragments' room (on a large mesh's cube the raw fragments are
// several times the kept ones, and would otherwise stay resident through the render).
void compact(ViewBuild* vb) {
  vb->bins = std::vector<BinEntry>();
  const size_t pixels = vb->view.pixel_count();
  uint32_t write = 0;
  for (size_t p = 0; p < pixels; ++p) {
    const uint32_t from = vb->offsets[p], n = vb->cursor[p];
    if (write != from && n > 0) std::memmove(&vb->fragments[write], &vb->fragments[from], n * sizeof(Fragment));
    vb->offsets[p] = write;
    write += n;
  }
  vb->offsets[pixels] = write;
  vb->cursor = std::vector<uint32_t>();
  vb->fragments.resize(write);
  vb->fragments.shrink_to_fit();
}

std::string mib(uint64_t bytes) { return std::to_string((bytes + MIB - 1) / MIB); }

void check_options(const ABufferOptions& o) {
  if (o.threads < 0) throw InputError("A-buffer: threads must be >= 0, got " + std::to_string(o.threads));
  if (!(o.near_distance >= 0.0) || !std::isfinite(o.near_distance)) {
    throw InputError("A-buffer: near distance must be finite and >= 0, got " + std::to_string(o.near_distance));
  }
}

// Count pass over every band of every view, then prefix sums; returns the raw total.
uint64_t count_views(const TriangleSoup& soup, std::vector<ViewBuild>* views, const std::vector<Band>& bands,
                     int threads) {
  parallel_for(bands.size(), threads, [&](size_t i, int) { count_band(soup, &(*views)[bands[i].view], bands[i]); });
  uint64_t total = 0;
  for (ViewBuild& vb : *views) {
    uint64_t sum = 0;
    for (size_t p = 1; p < vb.offsets.size(); ++p) {
      sum += vb.offsets[p];
      if (sum > std::numeric_limits<uint32_t>::max()) {
        throw InputError("A-buffer: more than 2^32 fragments in one view (" + std::to_string(vb.view.width) + "x" +
                         std::to_string(vb.view.height) + "); lower the resolution");
      }
      vb.offsets[p] = static_cast<uint32_t>(sum);
    }
    total += sum;
  }
  return total;
}

// The triangles no view binned: culled, degenerate or edge-on (read before compact()
// frees the bins).
uint64_t unbinned_triangles(const std::vector<ViewBuild>& views, size_t triangles) {
  std::vector<unsigned char> seen(triangles, 0);
  for (const ViewBuild& vb : views) {
    for (const BinEntry& b : vb.bins) seen[b.triangle] = 1;
  }
  return static_cast<uint64_t>(std::count(seen.begin(), seen.end(), 0));
}

// The counters of ABufferStats from the finished build.
ABufferStats summarise(const std::vector<ViewBuild>& views, const std::vector<ABuffer>& out,
                       const std::vector<BandResult>& results, uint64_t unbinned) {
  ABufferStats st;
  for (const ViewBuild& vb : views) {
    st.triangle_views += vb.triangle_views;
    st.triangles_clipped += vb.clipped;
  }
  st.triangles_degenerate = views.front().degenerate;  // the same in every view of one centre
  st.triangles_edge_on = views.front().edge_on;
  st.triangles_culled = unbinned - st.triangles_degenerate - st.triangles_edge_on;
  for (const BandResult& r : results) {
    st.dropped_by_cap += r.dropped;
    st.max_list_length = std::max(st.max_list_length, r.max_list);
  }
  for (const ABuffer& b : out) {
    st.fragments_per_view.push_back(b.fragments.size());
    st.fragments += b.fragments.size();
    st.bytes_total += b.fragments.size() * sizeof(Fragment) + b.offsets.size() * sizeof(uint32_t);
  }
  return st;
}

std::vector<ABuffer> build_views(const SceneData& scene, std::vector<RasterView> rasters, const char* what,
                                 const ABufferOptions& options, ABufferStats* stats,
                                 const std::vector<uint8_t>* views_of_triangle = nullptr) {
  const Clock::time_point start = Clock::now();
  const TriangleSoup& soup = *scene.triangles;
  std::vector<ViewBuild> views(rasters.size());
  std::vector<Band> bands;
  uint64_t index_bytes = 0;
  for (size_t v = 0; v < rasters.size(); ++v) {
    views[v].view = rasters[v];
    index_bytes += (2 * rasters[v].pixel_count() + 1) * sizeof(uint32_t);
    for (int y = 0; y < rasters[v].height; y += BAND_ROWS)
      bands.push_back({v, y, std::min(y + BAND_ROWS, rasters[v].height)});
  }
  const uint64_t budget = memory_budget_bytes(options.max_memory_bytes);
  check_abuffer_budget(what, index_bytes, "its per-pixel index alone", options, budget);
  const int threads = thread_count(options.threads, bands.size());

  const uint8_t* masks = views_of_triangle ? views_of_triangle->data() : nullptr;
  parallel_for(views.size(), threads, [&](size_t v, int) { bin_view(soup, masks, static_cast<int>(v), &views[v]); });
  for (ViewBuild& vb : views) vb.offsets.assign(vb.view.pixel_count() + 1, 0);
  const uint64_t raw = count_views(soup, &views, bands, threads);
  const double count_ms = ms_since(start);

  uint64_t bin_bytes = 0;
  for (const ViewBuild& vb : views) bin_bytes += vb.bins.size() * sizeof(BinEntry);
  const uint64_t estimate = raw * sizeof(Fragment) + index_bytes + bin_bytes;
  check_abuffer_budget(what, estimate,
                       std::to_string(raw) + " fragments at " + std::to_string(sizeof(Fragment)) + " bytes", options,
                       budget);
  for (ViewBuild& vb : views) {
    vb.cursor.assign(vb.view.pixel_count(), 0);
    vb.fragments.resize(vb.offsets.back());
  }
  std::vector<BandResult> results(bands.size());
  parallel_for(bands.size(), threads,
               [&](size_t i, int) { results[i] = fill_band(soup, options, &views[bands[i].view], bands[i]); });
  const uint64_t unbinned = stats ? unbinned_triangles(views, soup.triangle_count()) : 0;
  parallel_for(views.size(), threads, [&](size_t v, int) { compact(&views[v]); });

  std::vector<ABuffer> out(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    out[v].view = views[v].view;
    out[v].offsets = std::move(views[v].offsets);
    out[v].fragments = std::move(views[v].fragments);
  }
  if (stats) {
    *stats = summarise(views, out, results, unbinned);
    stats->raw_fragments = raw;
    stats->estimated_bytes = estimate;
    stats->budget_bytes = budget;
    stats->near_distance = rasters.front().near_distance;
    stats->count_ms = count_ms;
    stats->total_ms = ms_since(start);
    stats->fill_ms = stats->total_ms - count_ms;
    stats->threads = threads;
  }
  return out;
}

}  // namespace

uint32_t finish_fragment_list(const TriangleSoup& soup, const ABufferOptions& options, Fragment* list, uint32_t count,
                              uint64_t* dropped) {
  std::sort(list, list + count, before);
  uint32_t kept = 0;
  bool merged_any = false;
  float reach = -1.0f;  // the largest zmax kept so far: no overlap in z beyond it
  for (uint32_t i = 0; i < count; ++i) {
    bool merged = false;
    const bool may_merge = options.merge && list[i].zmin <= reach;
    for (uint32_t j = 0; may_merge && j < kept && !merged; ++j) {
      if (mergeable(soup, list[j], list[i])) {
        merge_into(&list[j], list[i]);
        merged = merged_any = true;
      }
    }
    reach = std::max(reach, list[i].zmax);
    if (!merged) list[kept++] = list[i];
  }
  if (merged_any) std::sort(list, list + kept, before);  // a merge may change the tie key
  if (options.max_layers > 0 && kept > options.max_layers) {
    *dropped += kept - options.max_layers;
    kept = options.max_layers;
  }
  return kept;
}

void check_abuffer_budget(const char* what, uint64_t need, const std::string& detail, const ABufferOptions& o,
                          uint64_t budget) {
  if (need <= budget && o.reserved_bytes <= budget - need) return;
  const std::string beside =
      o.reserved_bytes > 0 ? " beside " + mib(o.reserved_bytes) + " MiB for the rest of the render" : "";
  throw InputError(std::string(what) + " needs " + mib(need) + " MiB (" + detail + ")" + beside + ", " +
                   budget_words(budget, o.max_memory_bytes > 0));
}

std::vector<uint8_t> triangle_cube_faces(const TriangleSoup& soup, const glm::dvec3& centre, int threads) {
  std::vector<uint8_t> faces_of(soup.triangle_count());
  parallel_for_runs(faces_of.size(), size_t{1} << 14, threads, [&](size_t t) {
    const uint32_t k = static_cast<uint32_t>(t);
    faces_of[t] = triangle_shape(centre, soup, k) == SetupResult::visible ? cube_faces_of(centre, soup, k)
                                                                          : uint8_t{(1u << CUBE_FACES) - 1};
  });
  return faces_of;
}

double abuffer_near_distance(const SceneData& scene, const glm::dvec3& centre, const ABufferOptions& options) {
  check_options(options);
  return options.near_distance > 0.0 ? options.near_distance : default_near_distance(max_distance_from(scene, centre));
}

std::vector<RasterView> cube_build_views(const char* what, const SceneData& scene, const glm::dvec3& centre, int n,
                                         const ABufferOptions& options) {
  if (n < 1) throw InputError(std::string(what) + ": resolution must be >= 1, got " + std::to_string(n));
  if (!std::isfinite(centre.x) || !std::isfinite(centre.y) || !std::isfinite(centre.z)) {
    throw InputError(std::string(what) + ": the centre must be finite");
  }
  const double near = abuffer_near_distance(scene, centre, options);
  std::vector<RasterView> rasters;
  for (int f = 0; f < CUBE_FACES; ++f) rasters.push_back(cube_face_view(f, centre, n, near));
  return rasters;
}

CubeABuffer build_cube_abuffer(const SceneData& scene, const glm::dvec3& centre, int n, const ABufferOptions& options,
                               ABufferStats* stats) {
  std::vector<RasterView> rasters = cube_build_views("cube A-buffer", scene, centre, n, options);
  const double near = rasters.front().near_distance;
  // Each triangle's faces first (one byte a triangle, for the build): most triangles lie in
  // one face's pyramid, and the five other faces then skip them unset up.
  std::vector<uint8_t> faces_of = triangle_cube_faces(*scene.triangles, centre, options.threads);
  std::vector<ABuffer> faces = build_views(scene, std::move(rasters), "cube A-buffer", options, stats, &faces_of);
  faces_of = std::vector<uint8_t>();
  // The build's bins and its workers' small blocks, freed in their threads' heaps: handed
  // back before the searches' own structures are built, so that they do not stay resident
  // through the render's peak (bench/memory.py measures it).
  release_free_memory();
  return cube_of_faces(n, centre, near, std::move(faces));
}

CubeABuffer cube_of_faces(int n, const glm::dvec3& centre, double near_distance, std::vector<ABuffer> faces) {
  ABCUBE_CHECK(faces.size() == CUBE_FACES, "cube_of_faces: six faces");
  CubeABuffer cube;
  cube.n = n;
  cube.centre = centre;
  cube.near_distance = near_distance;
  for (size_t f = 0; f < faces.size(); ++f) cube.faces[f] = std::move(faces[f]);
  return cube;
}

ABuffer build_camera_abuffer(const SceneData& scene, const ABufferOptions& options, ABufferStats* stats) {
  const CameraFrame frame = make_camera_frame(scene.camera);
  const double near = abuffer_near_distance(scene, frame.eye, options);
  std::vector<ABuffer> one = build_views(scene, {camera_view(frame, near)}, "camera A-buffer", options, stats);
  return std::move(one.front());
}

const Fragment* centre_fragment(const ABuffer& buffer, int x, int y) {
  for (const Fragment& f : buffer.list(x, y)) {
    if ((f.mask & CENTRE_SAMPLES) != 0) return &f;
  }
  return nullptr;
}

namespace {

// nearest_layer for one face.
void nearest_layer_face(const CubeABuffer& cube, const TriangleSoup& triangles, int face, NearestLayer* out) {
  const ABuffer& b = cube.faces[static_cast<size_t>(face)];
  Image& distance = out->distance.faces[static_cast<size_t>(face)];
  std::vector<uint32_t>& ids = out->object.faces[static_cast<size_t>(face)];
  ids.assign(static_cast<size_t>(cube.n) * static_cast<size_t>(cube.n), std::numeric_limits<uint32_t>::max());
  std::vector<uint32_t>& tied = out->tied.faces[static_cast<size_t>(face)];
  tied.assign(static_cast<size_t>(cube.n) * static_cast<size_t>(cube.n), 0);
  for (int y = 0; y < cube.n; ++y) {
    for (int x = 0; x < cube.n; ++x) {
      const glm::dvec3 d = glm::normalize(b.view.direction(x + 0.5, y + 0.5));
      double best = HUGE_VAL;
      uint32_t best_id = std::numeric_limits<uint32_t>::max(), best_triangle = 0;
      CoverageMask best_mask = 0;
      auto covers_centre = [&](uint32_t triangle) {  // only at a tie: not on the common path
        TriangleHit hit;
        return intersect_triangle(RayQuery(cube.centre, d), triangles, triangle, HUGE_VAL, &hit);
      };
      for (const Fragment& f : b.list(x, y)) {
        if ((f.mask & CENTRE_SAMPLES) == 0) continue;
        const glm::dvec3 r = point_on_triangle_plane(b.view, triangles, f.triangle(), x + 0.5, y + 0.5) - cube.centre;
        const double dist = glm::length(r);
        if (!(glm::dot(r, d) > 0.0)) continue;
        bool nearer = best == HUGE_VAL;
        if (!nearer && f.triangle() != best_triangle &&
            same_distance(triangles, d, {f.triangle(), dist}, {best_triangle, best})) {
          // Two surfaces at the same distance over the centre samples: coplanar triangles
          // meeting at an edge that passes between those samples, or coincident ones. The
          // one whose triangle holds the texel centre itself is what a prepass sampling
          // the centre sees (the exact ray test); where both or neither do, THE TIE RULE
          // (scene/tie_rule.hpp): the later object.
          const bool f_covers = covers_centre(f.triangle()), best_covers = covers_centre(best_triangle);
          nearer = f_covers != best_covers ? f_covers : ranks_above(triangles, f.triangle(), best_triangle);
        } else if (!nearer) {
          nearer = seen_before(triangles, d, {f.triangle(), dist}, {best_triangle, best});
        }
        if (nearer) {
          best = dist;
          best_id = triangles.object_id[f.triangle()];
          best_triangle = f.triangle();
          best_mask = f.mask;
        }
      }
      if (best < HUGE_VAL) distance.at(x, y)[0] = static_cast<float>(best);
      const size_t texel = static_cast<size_t>(y) * static_cast<size_t>(cube.n) + static_cast<size_t>(x);
      ids[texel] = best_id;
      // A tie: another object's surface over one of the same centre samples at the same
      // distance (the rule decided; surfaces meeting at an edge cover disjoint samples).
      for (const Fragment& f : b.list(x, y)) {
        if (best == HUGE_VAL || (f.mask & best_mask & CENTRE_SAMPLES) == 0 ||
            triangles.object_id[f.triangle()] == best_id) {
          continue;
        }
        const glm::dvec3 r = point_on_triangle_plane(b.view, triangles, f.triangle(), x + 0.5, y + 0.5) - cube.centre;
        if (glm::dot(r, d) > 0.0 &&
            same_distance(triangles, d, {f.triangle(), glm::length(r)}, {best_triangle, best})) {
          tied[texel] = 1;
          break;
        }
      }
    }
  }
}

}  // namespace

NearestLayer nearest_layer(const CubeABuffer& cube, const TriangleSoup& triangles) {
  NearestLayer out;
  out.distance = CubeImage(cube.n, 1, std::numeric_limits<float>::infinity());
  out.object.n = cube.n;
  out.tied.n = cube.n;
  parallel_for(CUBE_FACES, thread_count(0, CUBE_FACES),
               [&](size_t face, int) { nearest_layer_face(cube, triangles, static_cast<int>(face), &out); });
  return out;
}

glm::dvec3 fragment_point(const ABuffer& buffer, const TriangleSoup& triangles, const Fragment& f, int x, int y) {
  const glm::dvec2 c = mask_centroid(f.mask);
  return point_on_triangle_plane(buffer.view, triangles, f.triangle(), x + c.x, y + c.y);
}

}  // namespace abcube
