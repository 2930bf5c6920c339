// DEFERRED SEARCHES (header): the answers by ray, the queue of rays not yet answered, and the
// batches that answer them.
#include "search/deferred_searches.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <string>
#include <vector>
#include <unordered_set>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"

namespace abcube {

namespace deferred {  // named: DeferredSearches::Store holds these

// A ray as the searches see it, bit for bit: its SearchRay and, for a shadow segment, the
// light. Two rays with the same key have the same answer.
struct RayKey {
  std::array<uint64_t, 13> bits{};
  bool operator==(const RayKey& o) const { return bits == o.bits; }
};

struct RayKeyHash {
  size_t operator()(const RayKey& k) const {
    uint64_t h = 0xcbf29ce484222325ull;
    for (const uint64_t v : k.bits) h = (h ^ v ^ (v >> 31)) * 0x100000001b3ull;
    // The low bits pick a table's slot: every bit of h mixed into them.
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdull;
    return static_cast<size_t>(h ^ (h >> 33));
  }
};

// The answers by ray: open addressing over a power-of-two table of slots (a key's hash and
// its entry's number), the entries (key beside answer) in chunks in the order stored, so that
// a lookup reads a slot and an entry, and storing never moves an entry. Filled only between
// passes; read by every thread during one. At most half the slots are taken.
template <class Answer>
class AnswerTable {
 public:
  const Answer* find(const RayKey& k, uint64_t h) const {
    if (slots_.empty()) return nullptr;
    for (size_t i = h & mask_;; i = (i + 1) & mask_) {
      const Slot& s = slots_[i];
      if (s.entry == 0) return nullptr;
      if (s.hash == h && entry(s.entry - 1).key == k) return &entry(s.entry - 1).answer;
    }
  }
  // Stores k's answer unless k has one.
  void insert(const RayKey& k, uint64_t h, const Answer& a) {
    if (find(k, h)) return;
    if (2 * (count_ + 1) > slots_.size()) grow();
    if (count_ % CHUNK == 0) {
      chunks_.emplace_back();
      chunks_.back().reserve(CHUNK);
    }
    chunks_.back().push_back({k, a});
    place(h, ++count_);
  }
  size_t size() const { return count_; }

 private:
  static constexpr size_t CHUNK = 4096;
  struct Slot {
    uint64_t hash = 0;
    uint64_t entry = 0;  // its number + 1; 0: empty
  };
  struct Entry {
    RayKey key;
    Answer answer;
  };
  const Entry& entry(uint64_t n) const { return chunks_[n / CHUNK][n % CHUNK]; }
  void place(uint64_t h, uint64_t entry_plus_one) {
    size_t i = h & mask_;
    while (slots_[i].entry != 0) i = (i + 1) & mask_;
    slots_[i] = {h, entry_plus_one};
  }
  void grow() {
    std::vector<Slot> old(std::max<size_t>(64, 2 * slots_.size()));
    old.swap(slots_);
    mask_ = slots_.size() - 1;
    for (const Slot& s : old) {
      if (s.entry != 0) place(s.hash, s.entry);
    }
  }
  std::vector<Slot> slots_;
  size_t mask_ = 0;
  std::vector<std::vector<Entry>> chunks_;
  size_t count_ = 0;
};

RayKey key_of(const SearchRay& q, const glm::dvec3* light) {
  RayKey k;
  size_t i = 0;
  const auto put = [&](double v) { std::memcpy(&k.bits[i++], &v, sizeof v); };
  for (int c = 0; c < 3; ++c) put(q.w[c]);
  for (int c = 0; c < 3; ++c) put(q.d[c]);
  put(q.l_max);
  put(q.self);
  put(q.self_tolerance);
  for (int c = 0; c < 3; ++c) put(light ? (*light)[c] : 0.0);
  k.bits[i] = (uint64_t{q.object} << 8) | (q.restrict_object ? 1u : 0u) | (q.side ? 2u : 0u) | (light ? 4u : 0u);
  return k;
}

}  // namespace deferred

namespace {
// What every DeferredSearches did on this thread (DeferredSearches::tally_here).
thread_local DeferredTally tally_on_thread;
}  // namespace

using deferred::AnswerTable;
using deferred::key_of;
using deferred::RayKey;
using deferred::RayKeyHash;

struct DeferredSearches::Queued {
  SearchRay ray;
  glm::dvec3 light{0.0};
  bool shadow = false;
};

struct DeferredSearches::Store {
  // Written only by answer_queued, between passes: a pass reads them from every thread.
  AnswerTable<SearchResult> searches;
  AnswerTable<ShadowResult> shadows;
  mutable std::mutex mutex;  // the queue's
  std::unordered_set<RayKey, RayKeyHash> queued_keys;
  std::vector<Queued> queue;
  uint64_t max_bytes = 0;
  DeferredSearchStats stats;

  uint64_t held_bytes() const { return (searches.size() + shadows.size() + queue.size()) * DEFERRED_ENTRY_BYTES; }
  // Queues q (once); false, queueing nothing, when the store has no room for it.
  bool enqueue(const RayKey& k, const Queued& q) {
    const std::lock_guard<std::mutex> lock(mutex);
    if (queued_keys.count(k)) return true;
    if (max_bytes > 0 && held_bytes() + DEFERRED_ENTRY_BYTES > max_bytes) return false;
    queued_keys.insert(k);
    queue.push_back(q);
    stats.bytes = std::max(stats.bytes, held_bytes());
    return true;
  }
};

// While a batch is answered its queue entries and its answers are held together.
static_assert(sizeof(RayKey) + sizeof(SearchResult) + sizeof(DeferredSearches::Queued) + 64 <= DEFERRED_ENTRY_BYTES,
              "DEFERRED_ENTRY_BYTES covers a ray's key, answer, queue entry and table share");

CandidateScanner cpu_candidate_scanner(const SearchContext& ctx, int threads) {
  return [&ctx, threads](const std::vector<SearchRay>& rays, const SearchOptions& options,
                         const std::vector<ScanStop>& stops) {
    std::vector<CandidateScan> out(rays.size());
    parallel_for(rays.size(), thread_count(threads, rays.size()), [&](size_t k, int) {
      out[k] = scan_candidates(ctx, rays[k], options, stops.empty() ? ScanStop::none : stops[k]);
    });
    return out;
  };
}

DeferredSearches::DeferredSearches(const SearchContext& ctx, const SearchOptions& options, CandidateScanner scanner,
                                   const DeferredSearchOptions& deferred)
    : ctx_(ctx),
      options_(options),
      scanner_(std::move(scanner)),
      deferred_(deferred),
      store_(std::make_unique<Store>()) {
  if (options.mode != SearchMode::crossing || options.layers != SearchLayers::all) {
    throw InputError("deferred searches: the crossing mode over all layers only");
  }
  deferred_.batch_rays = std::max<size_t>(deferred_.batch_rays, 1);
  store_->max_bytes = deferred.max_bytes;
}

DeferredSearches::~DeferredSearches() = default;

SearchResult DeferredSearches::search(const SearchRay& q) {
  const RayKey k = key_of(q, nullptr);
  if (const SearchResult* found = store_->searches.find(k, RayKeyHash()(k))) {
    ++tally_on_thread.used;
    return *found;
  }
  if (store_->enqueue(k, {q, glm::dvec3(0.0), false})) {
    ++tally_on_thread.stand_ins;
    return SearchResult{};  // a miss
  }
  ++tally_on_thread.walked_now;
  return search_along(ctx_, q, options_);
}

ShadowResult DeferredSearches::shadow(const SearchRay& q, const glm::dvec3& light_position) {
  const RayKey k = key_of(q, &light_position);
  if (const ShadowResult* found = store_->shadows.find(k, RayKeyHash()(k))) {
    ++tally_on_thread.used;
    return *found;
  }
  if (store_->enqueue(k, {q, light_position, true})) {
    ++tally_on_thread.stand_ins;
    return ShadowResult{};  // the light let through
  }
  ++tally_on_thread.walked_now;
  return shadow_along(ctx_, q, light_position, options_);
}

DeferredTally DeferredSearches::tally_here() { return tally_on_thread; }

void DeferredSearches::begin_pass() { ++store_->stats.passes; }

void DeferredSearches::note_image(uint64_t answers_used, uint64_t walked_now, uint64_t rows_shaded,
                                  uint64_t edge_rows_shaded) {
  store_->stats.answers_used = answers_used;
  store_->stats.walked_now = walked_now;
  store_->stats.rows_shaded = rows_shaded;
  store_->stats.edge_rows_shaded = edge_rows_shaded;
}

size_t DeferredSearches::queued() const {
  const std::lock_guard<std::mutex> lock(store_->mutex);
  return store_->queue.size();
}

void DeferredSearches::answer_queued() {
  std::vector<Queued> queue;
  {
    const std::lock_guard<std::mutex> lock(store_->mutex);
    queue.swap(store_->queue);
    store_->queued_keys.clear();
  }
  // STOP HINTS (search.hpp): each ray scanned to where its search likely stops; a ray whose
  // answer needs more is scanned again, whole.
  std::vector<const Queued*> items, left;
  for (size_t first = 0; first < queue.size(); first += deferred_.batch_rays) {
    const size_t count = std::min(deferred_.batch_rays, queue.size() - first);
    items.resize(count);
    for (size_t k = 0; k < count; ++k) items[k] = &queue[first + k];
    left.clear();
    scan_and_answer(items, deferred_.stop_hints, deferred_.stop_hints ? &left : nullptr);
    store_->stats.rescanned += left.size();
    if (!left.empty()) scan_and_answer(left, false, nullptr);
    store_->stats.rays += count;
  }
}

void DeferredSearches::scan_and_answer(const std::vector<const Queued*>& items, bool stop_hints,
                                       std::vector<const Queued*>* left) {
  Store& s = *store_;
  std::vector<SearchRay> rays(items.size());
  std::vector<ScanStop> stops(stop_hints ? items.size() : 0);
  for (size_t k = 0; k < items.size(); ++k) {
    rays[k] = items[k]->ray;
    if (stop_hints) stops[k] = items[k]->shadow ? ScanStop::shadow : ScanStop::crossing;
  }
  Clock::time_point t0 = Clock::now();
  const std::vector<CandidateScan> scans = scanner_(rays, options_, stops);
  s.stats.scan_ms += ms_since(t0);
  ++s.stats.batches;
  if (scans.size() != items.size()) {
    throw RuntimeFailure("deferred searches: the scanner gave " + std::to_string(scans.size()) + " scans for " +
                         std::to_string(items.size()) + " rays");
  }
  t0 = Clock::now();
  std::vector<SearchResult> found(items.size());
  std::vector<ShadowResult> shadowed(items.size());
  std::vector<uint8_t> complete(items.size(), 1);
  parallel_for(items.size(), thread_count(deferred_.threads, items.size()), [&](size_t k, int) {
    const Queued& q = *items[k];
    bool whole = true;
    if (q.shadow) {
      shadowed[k] = shadow_from_candidates(ctx_, q.ray, q.light, options_, scans[k], &whole);
    } else {
      found[k] = search_from_candidates(ctx_, q.ray, options_, scans[k], &whole);
    }
    complete[k] = whole || !left ? 1 : 0;
  });
  for (size_t k = 0; k < items.size(); ++k) {
    const Queued& q = *items[k];
    s.stats.candidates += scans[k].candidates.size();
    s.stats.texels += scans[k].texels;
    s.stats.stopped += scans[k].stopped ? 1 : 0;
    if (!complete[k]) {
      left->push_back(&q);
    } else if (q.shadow) {
      const RayKey key = key_of(q.ray, &q.light);
      s.shadows.insert(key, RayKeyHash()(key), shadowed[k]);
    } else {
      const RayKey key = key_of(q.ray, nullptr);
      s.searches.insert(key, RayKeyHash()(key), found[k]);
    }
  }
  s.stats.answer_ms += ms_since(t0);
}

DeferredSearchStats DeferredSearches::stats() const { return store_->stats; }

}  // namespace abcube
