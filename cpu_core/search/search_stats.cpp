// Counters of the searches (search.hpp SearchKindStats, SearchStats), the options'
// names and the self offset each mode defaults to.
#include <algorithm>
#include <cstring>

#include "search/search.hpp"
#include "base/enum_names.hpp"

namespace abcube {

double self_offset_texels(const SearchOptions& o) {
  if (o.self_offset_texels > 0.0) return o.self_offset_texels;
  return o.mode == SearchMode::thesis ? SELF_OFFSET_THESIS_TEXELS : SELF_OFFSET_CROSSING_TEXELS;
}

namespace {

constexpr EnumName<SearchMode> SEARCH_MODE_NAMES[] = {{SearchMode::crossing, "crossing"},
                                                      {SearchMode::thesis, "thesis"}};
constexpr EnumName<SearchRefine> SEARCH_REFINE_NAMES[] = {{SearchRefine::mesh, "mesh"}, {SearchRefine::plane, "plane"}};
constexpr EnumName<MissReason> MISS_REASON_NAMES[] = {{MissReason::none, "none"},
                                                      {MissReason::no_crossing, "no_crossing"},
                                                      {MissReason::threshold_rejection, "threshold_rejection"},
                                                      {MissReason::zero_area_surface, "zero_area_surface"},
                                                      {MissReason::aborted, "aborted"}};

}  // namespace

const char* search_mode_name(SearchMode m) { return enum_name(SEARCH_MODE_NAMES, m); }

bool parse_search_mode(const std::string& s, SearchMode* out) { return parse_enum(SEARCH_MODE_NAMES, s, out); }

const char* search_refine_name(SearchRefine r) { return enum_name(SEARCH_REFINE_NAMES, r); }

bool parse_search_refine(const std::string& s, SearchRefine* out) { return parse_enum(SEARCH_REFINE_NAMES, s, out); }

const char* miss_reason_name(MissReason r) { return enum_name(MISS_REASON_NAMES, r); }

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(const glm::dvec3& a, const glm::dvec3& b) {
  return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z);
}

}  // namespace

bool same_answer(const SearchResult& a, const SearchResult& b) {
  return a.hit == b.hit && a.miss == b.miss && a.triangle == b.triangle && a.object_id == b.object_id &&
         a.material_id == b.material_id && a.back_face == b.back_face && same_bits(a.point, b.point) &&
         same_bits(a.distance, b.distance) && same_bits(a.angle, b.angle) &&
         same_bits(a.outside_texels, b.outside_texels) && a.side == b.side && a.texel.face == b.texel.face &&
         a.texel.i == b.texel.i && a.texel.j == b.texel.j && a.fragments_tested == b.fragments_tested &&
         a.candidates == b.candidates;
}

namespace {

// same_answer, the walk's counts of texels, nodes and fragments read taken from `walked`.
template <class Result>
bool same_but_walk(const Result& walked, Result from_candidates) {
  from_candidates.texels_visited = walked.texels_visited;
  from_candidates.nodes_skipped = walked.nodes_skipped;
  from_candidates.fragments_tested = walked.fragments_tested;
  return same_answer(walked, from_candidates);
}

}  // namespace

bool same_found(const SearchResult& walked, const SearchResult& from_candidates) {
  return same_but_walk(walked, from_candidates);
}
bool same_found(const ShadowResult& walked, const ShadowResult& from_candidates) {
  return same_but_walk(walked, from_candidates);
}

bool same_answer(const ShadowResult& a, const ShadowResult& b) {
  return same_bits(a.transmittance, b.transmittance) && a.blocked == b.blocked && a.blockers == b.blockers &&
         a.first_blocker == b.first_blocker && a.aborted == b.aborted && a.zero_area == b.zero_area &&
         a.side_blockers == b.side_blockers && a.opaque_blocker == b.opaque_blocker &&
         a.known_blocker == b.known_blocker && a.fragments_tested == b.fragments_tested &&
         a.candidates == b.candidates && a.threshold_rejections == b.threshold_rejections;
}

namespace {

// The walk's counts, which every kind of result carries.
template <class Result>
void add_walk(SearchKindStats* s, const Result& r) {
  ++s->rays;
  s->texels += r.texels_visited;
  s->max_texels = std::max<uint64_t>(s->max_texels, r.texels_visited);
  s->nodes += r.nodes_skipped;
  s->fragments += r.fragments_tested;
  s->candidates += r.candidates;
  s->mesh_triangles += r.mesh_triangles;
}

}  // namespace

void SearchKindStats::add(const SearchResult& r) {
  add_walk(this, r);
  if (r.hit) {
    ++hits;
    side_hits += r.side;
    return;
  }
  ++misses;
  threshold_rejections += r.miss == MissReason::threshold_rejection;
  zero_area += r.miss == MissReason::zero_area_surface;
  aborted += r.miss == MissReason::aborted;
}

void SearchKindStats::add(const ShadowResult& r) {
  add_walk(this, r);
  if (r.blockers > 0)
    ++hits;
  else
    ++misses;
  threshold_rejections += r.blockers == 0 && r.threshold_rejections > 0;
  zero_area += r.zero_area;
  side_hits += r.side_blockers > 0;
  known_blockers += r.known_blocker;
  aborted += r.aborted;
}

void SearchKindStats::merge(const SearchKindStats& o) {
  rays += o.rays;
  texels += o.texels;
  max_texels = std::max(max_texels, o.max_texels);
  nodes += o.nodes;
  fragments += o.fragments;
  candidates += o.candidates;
  mesh_triangles += o.mesh_triangles;
  hits += o.hits;
  misses += o.misses;
  threshold_rejections += o.threshold_rejections;
  zero_area += o.zero_area;
  side_hits += o.side_hits;
  known_blockers += o.known_blockers;
  aborted += o.aborted;
}

void SearchStats::merge(const SearchStats& o) {
  reflection.merge(o.reflection);
  refraction_exit.merge(o.refraction_exit);
  shadow.merge(o.shadow);
}

}  // namespace abcube
