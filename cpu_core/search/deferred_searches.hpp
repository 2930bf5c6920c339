// DEFERRED SEARCHES: a render's searches answered in batches, from candidates another
// scanner found (the GPU's: host/gl/gl_cube_scan.hpp), for a shader that asks one search at
// a time. A pass of the render asks its searches here. A ray answered by an earlier batch
// gets its answer; any other is queued and gets a stand-in (a miss; a shadow segment
// unblocked), and the pass goes on. Between passes the queued rays are scanned together and
// answered (search_from_candidates, shadow_from_candidates: the crossing choice the CPU's
// own walk runs). The render runs again until a pass queues nothing: every answer of that
// pass is then the search's own (same_found), so its image is the CPU searches' image, bit
// for bit.
//
// Why this ends: the rays of a pass depend only on the answers before them (the shading is
// a function of them, row by row). A pass's first stand-in is answered for the next pass, so
// the prefix of true answers grows every pass; the passes are as many as the longest chain
// of searches each asked on the answer of the last (a bounce, a quarter split on the first
// quarters' colours, an edge pass on the points' shadows), not as many as the searches.
// The stand-ins cost searches whose answers the image never takes (counted as unused).
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "search/search.hpp"

namespace abcube {

// What one ray holds in the store: its key, its answer or its place in the queue, and the
// hash table's share (DeferredSearchOptions::max_bytes counts these).
constexpr uint64_t DEFERRED_ENTRY_BYTES = 512;

// Every ray's scan_candidates(ctx, ray, options, stops[ray]), however computed (`stops`
// empty: ScanStop::none for all).
using CandidateScanner = std::function<std::vector<CandidateScan>(
    const std::vector<SearchRay>&, const SearchOptions& options, const std::vector<ScanStop>& stops)>;

// scan_candidates on the CPU, ray by ray (`threads` 0: every core): a scanner to check the
// deferred searches against, with no GL.
CandidateScanner cpu_candidate_scanner(const SearchContext& ctx, int threads);

struct DeferredSearchOptions {
  int threads = 0;               // answering the candidates; 0: every core
  size_t batch_rays = 1u << 16;  // the most rays one scanner call gets
  // The most bytes the answers and the queue may hold (0: no cap; DEFERRED_ENTRY_BYTES a
  // ray). A search that would pass it is walked at once by the CPU (the same answer), so a
  // large image's memory stays bounded and its image the same.
  uint64_t max_bytes = 0;
  // STOP HINTS (search.hpp): each batch's rays are scanned to where their search likely stops,
  // not to the end of their walk; a ray whose answer needs more (search_from_candidates'
  // `complete`) is scanned again, whole. Off: every walk scanned whole at once.
  bool stop_hints = true;
};

struct DeferredSearchStats {
  uint64_t passes = 0;     // render passes run (the last one asked nothing new)
  uint64_t batches = 0;    // scanner calls
  uint64_t rays = 0;       // rays scanned: searches and shadow segments
  uint64_t stopped = 0;    // scans a STOP HINT ended before their walk's end
  uint64_t rescanned = 0;  // rays scanned again whole, their answer past the hint
  uint64_t texels = 0;     // texels the scans walked
  uint64_t candidates = 0;
  // Of the searches the render's image took (note_image): those answered from the batches,
  // and those walked on the CPU at once, the store full.
  uint64_t answers_used = 0;
  uint64_t walked_now = 0;
  // The rows the passes' first stages shaded: each pass shades again only the rows that took
  // a stand-in in the last. And the rows with pixels the edge and sparse passes shaded: a row
  // whose pixels and force bits are the last pass's, and which took no stand-in, is kept.
  uint64_t rows_shaded = 0;
  uint64_t edge_rows_shaded = 0;
  uint64_t bytes = 0;  // the most the answers and the queue held
  double scan_ms = 0, answer_ms = 0;
};

// Searches answered by a DeferredSearches on one thread: with a stand-in, from a batch
// (used), or walked at once, the store full.
struct DeferredTally {
  uint64_t stand_ins = 0, used = 0, walked_now = 0;
};

class DeferredSearches {
 public:
  // The crossing mode over all layers only (search_from_candidates): InputError otherwise.
  DeferredSearches(const SearchContext& ctx, const SearchOptions& options, CandidateScanner scanner,
                   const DeferredSearchOptions& deferred = {});
  ~DeferredSearches();
  DeferredSearches(const DeferredSearches&) = delete;
  DeferredSearches& operator=(const DeferredSearches&) = delete;

  // search_along(ctx, q, options): the answer when a batch gave it, else a miss, with q queued
  // (or the walk's own answer when the store is full). Thread-safe within a pass.
  SearchResult search(const SearchRay& q);
  // shadow_along(ctx, q, light_position, options), the same way (a stand-in lets the light through).
  ShadowResult shadow(const SearchRay& q, const glm::dvec3& light_position);

  // What every DeferredSearches has done on the calling thread so far: a caller that reads
  // it before and after some shading knows which searches that shading took, and whether it
  // took only true answers (and would be the same in the next pass).
  static DeferredTally tally_here();
  // Sets the stats' answers_used and walked_now (the image's searches'), rows_shaded and
  // edge_rows_shaded (render_with_map).
  void note_image(uint64_t answers_used, uint64_t walked_now, uint64_t rows_shaded, uint64_t edge_rows_shaded);

  // Starts a pass: counts it and forgets which answers were asked.
  void begin_pass();
  // Rays queued since the last answer_queued.
  size_t queued() const;
  // Scans the queued rays in batches, answers them, and empties the queue. Not during a pass.
  void answer_queued();
  // The counts so far.
  DeferredSearchStats stats() const;

  struct Store;
  struct Queued;

 private:
  // Scans `items` (with their STOP HINTS, or whole) and stores their answers; with `left`, the
  // rays whose answer the scan cannot give (cut by a hint or the cap) go there instead.
  void scan_and_answer(const std::vector<const Queued*>& items, bool stop_hints, std::vector<const Queued*>* left);
  const SearchContext& ctx_;
  SearchOptions options_;
  CandidateScanner scanner_;
  DeferredSearchOptions deferred_;
  std::unique_ptr<Store> store_;
};

}  // namespace abcube
