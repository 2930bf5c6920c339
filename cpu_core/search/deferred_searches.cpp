// DEFERRED SEARCHES (header): the answers by ray, the queue of rays not yet answered, and the
// batches that answer them.
#include "search/deferred_searches.hpp"

#include <array>
#include <atomic>
#include <cstring>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"

namespace abcube {

namespace {

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
    return static_cast<size_t>(h ^ (h >> 29));
  }
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

struct Queued {
  SearchRay ray;
  glm::dvec3 light{0.0};
  bool shadow = false;
};

}  // namespace

struct DeferredSearches::Store {
  // Written only by answer_queued, between passes: a pass reads them from every thread.
  std::unordered_map<RayKey, SearchResult, RayKeyHash> searches;
  std::unordered_map<RayKey, ShadowResult, RayKeyHash> shadows;
  mutable std::mutex mutex;  // the queue's
  std::unordered_set<RayKey, RayKeyHash> queued_keys;
  std::vector<Queued> queue;
  std::atomic<uint64_t> used{0};
  DeferredSearchStats stats;

  void enqueue(const RayKey& k, const Queued& q) {
    const std::lock_guard<std::mutex> lock(mutex);
    if (queued_keys.insert(k).second) queue.push_back(q);
  }
};

CandidateScanner cpu_candidate_scanner(const SearchContext& ctx, int threads) {
  return [&ctx, threads](const std::vector<SearchRay>& rays, const SearchOptions& options) {
    std::vector<CandidateScan> out(rays.size());
    parallel_for(rays.size(), thread_count(threads, rays.size()),
                 [&](size_t k, int) { out[k] = scan_candidates(ctx, rays[k], options); });
    return out;
  };
}

DeferredSearches::DeferredSearches(const SearchContext& ctx, const SearchOptions& options, CandidateScanner scanner,
                                   int threads, size_t batch_rays)
    : ctx_(ctx),
      options_(options),
      scanner_(std::move(scanner)),
      threads_(threads),
      batch_rays_(std::max<size_t>(batch_rays, 1)),
      store_(std::make_unique<Store>()) {
  if (options.mode != SearchMode::crossing || options.layers != SearchLayers::all) {
    throw InputError("deferred searches: the crossing mode over all layers only");
  }
}

DeferredSearches::~DeferredSearches() = default;

SearchResult DeferredSearches::search(const SearchRay& q) {
  const RayKey k = key_of(q, nullptr);
  const auto it = store_->searches.find(k);
  if (it != store_->searches.end()) {
    store_->used.fetch_add(1, std::memory_order_relaxed);
    return it->second;
  }
  store_->enqueue(k, {q, glm::dvec3(0.0), false});
  return SearchResult{};  // a miss
}

ShadowResult DeferredSearches::shadow(const SearchRay& q, const glm::dvec3& light_position) {
  const RayKey k = key_of(q, &light_position);
  const auto it = store_->shadows.find(k);
  if (it != store_->shadows.end()) {
    store_->used.fetch_add(1, std::memory_order_relaxed);
    return it->second;
  }
  store_->enqueue(k, {q, light_position, true});
  return ShadowResult{};  // the light let through
}

void DeferredSearches::begin_pass() {
  ++store_->stats.passes;
  store_->used = 0;
}

size_t DeferredSearches::queued() const {
  const std::lock_guard<std::mutex> lock(store_->mutex);
  return store_->queue.size();
}

void DeferredSearches::answer_queued() {
  Store& s = *store_;
  std::vector<Queued> queue;
  {
    const std::lock_guard<std::mutex> lock(s.mutex);
    queue.swap(s.queue);
    s.queued_keys.clear();
  }
  std::vector<SearchRay> rays;
  std::vector<SearchResult> found;
  std::vector<ShadowResult> shadowed;
  for (size_t first = 0; first < queue.size(); first += batch_rays_) {
    const size_t count = std::min(batch_rays_, queue.size() - first);
    rays.resize(count);
    for (size_t k = 0; k < count; ++k) rays[k] = queue[first + k].ray;
    Clock::time_point t0 = Clock::now();
    const std::vector<CandidateScan> scans = scanner_(rays, options_);
    s.stats.scan_ms += ms_since(t0);
    if (scans.size() != count) {
      throw RuntimeFailure("deferred searches: the scanner gave " + std::to_string(scans.size()) + " scans for " +
                           std::to_string(count) + " rays");
    }
    t0 = Clock::now();
    found.assign(count, SearchResult{});
    shadowed.assign(count, ShadowResult{});
    parallel_for(count, thread_count(threads_, count), [&](size_t k, int) {
      const Queued& q = queue[first + k];
      if (q.shadow) {
        shadowed[k] = shadow_from_candidates(ctx_, q.ray, q.light, options_, scans[k]);
      } else {
        found[k] = search_from_candidates(ctx_, q.ray, options_, scans[k]);
      }
    });
    for (size_t k = 0; k < count; ++k) {
      const Queued& q = queue[first + k];
      if (q.shadow) {
        s.shadows.emplace(key_of(q.ray, &q.light), shadowed[k]);
      } else {
        s.searches.emplace(key_of(q.ray, nullptr), found[k]);
      }
      s.stats.candidates += scans[k].candidates.size();
    }
    s.stats.answer_ms += ms_since(t0);
    ++s.stats.batches;
    s.stats.rays += count;
  }
}

DeferredSearchStats DeferredSearches::stats() const {
  DeferredSearchStats out = store_->stats;
  out.answers_used = store_->used.load();
  return out;
}

}  // namespace abcube
