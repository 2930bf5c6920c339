// The report's page (report.cpp gathers its figures): one self-contained HTML file, its
// style, script and plots (inline SVG) in it, its images beside it, nothing from a network.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

namespace abcube {

// The page for report.json's content `report`. Every figure it shows is an element with
// data-key (its path in report.json, dots between keys) and data-value (the number as the
// JSON holds it), so that a test reads the page's figures back against the JSON.
std::string report_html(const nlohmann::json& report);

}  // namespace abcube
