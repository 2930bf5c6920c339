// DEFERRED SEARCHES (search/deferred_searches.hpp): what each stage of a render's pass left
// for the next pass, so that the next shades again only what can change. A render's pass
// has three stages: the first (every fragment at its points), the edge pass (the pixels a
// shadow's or a secondary surface's edge runs beside, shaded again with their samples) and
// the sparse pass (the pixels whose colour stands apart from a neighbour's). A row of a
// stage that took only true answers, and whose inputs are the same, is shaded the same in
// the next pass, bit for bit: its pixels and figures are kept instead.
#pragma once
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "io/image.hpp"
#include "search/deferred_searches.hpp"
#include "shading/map_shading.hpp"
#include "shading/secondary_edges.hpp"
#include "shading/shadow_edges.hpp"

namespace abcube {

// A stage's figures by row, and which rows took a stand-in (one resolve worker owns a row
// at a time, so a row's records need no lock).
struct RowRecords {
  std::vector<uint8_t> redo;  // per row: a stand-in was taken in it
  std::vector<MapShadingStats> stats;
  std::vector<DeferredTally> took;  // the searches each row took (used, walked_now)
  uint64_t rows_shaded = 0;         // rows with pixels shaded, over every pass

  // Every row to redo, no figures (a stage's first pass).
  void size(size_t rows) {
    redo.assign(rows, 1);
    stats.assign(rows, MapShadingStats{});
    took.assign(rows, DeferredTally{});
  }
  // Row y shaded afresh: its figures emptied.
  void start_row(size_t y) { stats[y] = MapShadingStats{}, took[y] = DeferredTally{}, redo[y] = 0; }
};

// An edge or sparse stage: the pixels it shaded, the force bits it shaded them with (the
// lights whose edge is searched, the secondary fragments shaded at their samples), and what
// they came out as. Its colours depend on nothing else but the answers and the lists.
struct StageRows {
  bool kept = false;
  RowRecords rows;
  std::vector<uint8_t> again;
  std::vector<uint64_t> forced;
  std::vector<uint8_t> forced_secondary;
  Image image;
  std::vector<std::pair<uint64_t, uint64_t>> pixel_searches;

  // Per row, whether to shade its pixels of `again` now: every row the first time; then a
  // row that took a stand-in, or where a pixel joins or leaves `again`, or is shaded with
  // other force bits (an empty vector: none).
  std::vector<uint8_t> rows_to_shade(int width, int height, const std::vector<uint8_t>& now,
                                     const std::vector<uint64_t>& forced_now,
                                     const std::vector<uint8_t>& forced_secondary_now) const {
    std::vector<uint8_t> out(static_cast<size_t>(height), 1);
    if (!kept) return out;
    for (size_t y = 0; y < out.size(); ++y) {
      bool same = !rows.redo[y];
      for (size_t p = y * static_cast<size_t>(width), end = p + static_cast<size_t>(width); same && p < end; ++p) {
        same = now[p] == again[p] &&
               (!now[p] || ((forced_now.empty() || forced_now[p] == forced[p]) &&
                            (forced_secondary_now.empty() || forced_secondary_now[p] == forced_secondary[p])));
      }
      out[y] = same ? 0 : 1;
    }
    return out;
  }
};

// The first stage: besides its rows' pixels and figures, what its pixels noted for the edge
// passes and their fallback counts. A row's first stage depends on nothing outside it but the
// answers, because its KNOWN BLOCKERS start afresh.
struct FirstStageRows {
  bool kept = false;  // false: no pass yet, every row to shade
  RowRecords rows;
  Image image;
  PixelShadows seen;
  PixelTrails trails;
  std::vector<std::pair<uint64_t, uint64_t>> pixel_searches;
  StageRows edges, sparse;   // the later stages of the same pass
  DeferredTally image_took;  // the whole image's, after its pass
};

}  // namespace abcube
