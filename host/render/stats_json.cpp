#include "render/stats_json.hpp"

#include <cmath>

namespace abcube {

using nlohmann::json;

json search_kind_json(const SearchKindStats& s) {
  return {{"rays", s.rays},
          {"texels_mean", s.mean_texels()},
          {"texels_max", s.max_texels},
          {"nodes_mean", s.mean_nodes()},
          {"fragments_tested", s.fragments},
          {"candidates", s.candidates},
          {"mesh_triangles", s.mesh_triangles},
          {"hits", s.hits},
          {"misses", s.misses},
          {"threshold_rejections", s.threshold_rejections},
          {"zero_area_misses", s.zero_area},
          {"side_hits", s.side_hits},
          {"known_blockers", s.known_blockers},
          {"aborted", s.aborted}};
}

json map_shading_json(const MapShadingStats& ms) {
  return {
      {"reflection", search_kind_json(ms.searches.reflection)},
      {"refraction_exit", search_kind_json(ms.searches.refraction_exit)},
      {"shadow", search_kind_json(ms.searches.shadow)},
      {"lens_transfers", ms.lens_transfers},
      {"lens_fallbacks", ms.lens_fallbacks},
      {"envmap_lookups", ms.envmap_lookups},
      {"shadow_edges",
       {{"multi_point_fragments", ms.multi_point_fragments},
        {"fragments", ms.shadow_edge_fragments},
        {"share", ms.multi_point_fragments ? double(ms.shadow_edge_fragments) / double(ms.multi_point_fragments) : 0.0},
        {"sample_searches", ms.shadow_edge_samples},
        {"pixels_shaded_again", ms.shadow_edge_pixels}}},
      {"secondary_edges",
       {{"fragments", ms.secondary_edge_fragments},
        {"share",
         ms.multi_point_fragments ? double(ms.secondary_edge_fragments) / double(ms.multi_point_fragments) : 0.0},
        {"samples_shaded", ms.secondary_edge_samples},
        {"pixels_shaded_again", ms.secondary_edge_pixels}}},
      {"sparse", {{"pixels_shaded_again", ms.sparse_pixels}}}};
}

json error_stats_json(const ErrorStats& e) {
  return {{"mean", e.mean()},   {"p99", e.percentile(0.99)}, {"max", e.max()},
          {"count", e.count()}, {"misses", e.miss_count()},  {"miss_share", e.miss_share()}};
}

json image_error_json(const ImageError& e) {
  const bool identical = !std::isfinite(e.psnr);
  const auto triple = [](const float* v) { return json::array({v[0], v[1], v[2]}); };
  return {
      {"rmse", e.rmse},
      {"psnr_db", identical ? json("inf") : json(e.psnr)},
      {"max_abs", e.max_abs},
      {"share_over_1_255", e.share_over_1},
      {"share_over_2_255", e.share_over_2},
      {"share_over_8_255", e.share_over_8},
      {"compared_as", "sRGB-encoded, clamped to [0,1] (metrics.hpp)"},
      {"worst_pixel",
       {{"x", e.worst_x},
        {"y", e.worst_y},
        {"channel", std::string(1, "RGB"[e.worst_channel])},
        {"a", triple(e.worst_a)},
        {"b", triple(e.worst_b)}}},
      {"linear",
       {{"rmse", e.linear_rmse}, {"max_abs", e.linear_max_abs}, {"relative_mean", e.relative_mean}, {"hdr", e.hdr}}}};
}

json abuffer_json(const ABufferStats& s, bool full) {
  if (!full) {
    return {{"fragments", s.fragments},
            {"bytes_per_fragment", s.bytes_per_fragment},
            {"max_list_length", s.max_list_length},
            {"dropped_by_cap", s.dropped_by_cap}};
  }
  return {{"fragments", s.fragments},
          {"raw_fragments", s.raw_fragments},
          {"max_list_length", s.max_list_length},
          {"bytes_per_fragment", s.bytes_per_fragment},
          {"bytes_total", s.bytes_total},
          {"dropped_by_cap", s.dropped_by_cap},
          {"triangles_degenerate", s.triangles_degenerate},
          {"triangles_clipped", s.triangles_clipped},
          {"triangles_culled", s.triangles_culled}};
}

json cube_abuffer_json(const ABufferStats& s) {
  return {{"fragments", s.fragments},
          {"raw_fragments", s.raw_fragments},
          {"max_list_length", s.max_list_length},
          {"bytes_total", s.bytes_total},
          {"dropped_by_cap", s.dropped_by_cap}};
}

std::map<std::string, double> tracer_timings(const RaytraceStats& rs) {
  return {{"bvh_build", rs.build_ms}, {"trace", rs.trace_ms}};
}

json raytrace_json(const RaytraceStats& rs) {
  return {{"counts",
           {{"primary_rays", rs.primary_rays}, {"secondary_rays", rs.secondary_rays}, {"shadow_rays", rs.shadow_rays}}},
          {"threads", rs.threads}};
}

}  // namespace abcube
