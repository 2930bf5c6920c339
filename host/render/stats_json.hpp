// The JSON form of the stats structures (the CLI's --stats file, RenderStats::json,
// the Python module's stats dict): one function per structure, beside nothing else.
#pragma once
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "io/metrics.hpp"
#include "raster/abuffer.hpp"
#include "reference/raytrace.hpp"
#include "search/search.hpp"
#include "shading/map_shading.hpp"

namespace abcube {

nlohmann::json search_kind_json(const SearchKindStats& s);
nlohmann::json map_shading_json(const MapShadingStats& s);  // the "searches" object
nlohmann::json error_stats_json(const ErrorStats& e);
nlohmann::json image_error_json(const ImageError& e);
// The camera A-buffer's figures; `full` adds the build's triangle counts (the local method).
nlohmann::json abuffer_json(const ABufferStats& s, bool full);
nlohmann::json cube_abuffer_json(const ABufferStats& s);
// The tracer's counts and threads (its timings are the RenderRecord's: tracer_timings).
nlohmann::json raytrace_json(const RaytraceStats& s);
std::map<std::string, double> tracer_timings(const RaytraceStats& s);

}  // namespace abcube
