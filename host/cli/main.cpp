// abcube: headless hybrid renderer. Subcommands: render, compare, info (../shared/cli.md).
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "cli/cli_common.hpp"
#include "base/error.hpp"

namespace {

const char* USAGE =
    "usage: abcube render SCENE.json -o OUT.png [--method abuffer|zbuffer|envmap|raytrace|gpu]\n"
    "                     [--cube-res N] [--max-depth D] [--threads K] [--gl auto|egl|egl-device|\n"
    "                     egl-surfaceless|osmesa|none] [--gl-device K] [--stats STATS.json] [--reference]\n"
    "                     [--max-layers K] [--max-memory MiB] [--search crossing|thesis]\n"
    "                     [--refine mesh|plane]\n"
    "                     [--theta-max DEG] [--refraction search|thick_lens|thin_lens]\n"
    "                     [--envmap-lookup R|bisector|position] [--fresnel] [--error-target E]\n"
    "                     [--reference-image REF.exr] [--plan needed|everything]\n"
    "       abcube compare A.png B.png [--diff HEAT.png] [--fail T] [--failpercent P]\n"
    "       abcube info\n"
    "       abcube export-pov SCENE.json -o OUT.pov\n"
    "       abcube crosscheck SCENE.json [--cube-res N] [--gl ...] [--threads K] [--stats STATS.json]\n";

// Every failure is reported on one line: embedded newlines (a GLSL log) become "; ".
std::string one_line(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  std::string out;
  for (char c : text) {
    if (c == '\n') {
      out += "; ";
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fputs("abcube: missing command (render, compare, info, export-pov, crosscheck; see abcube --help)\n", stderr);
    return 2;
  }
  if (!std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    std::fputs(USAGE, stdout);
    return 0;
  }
  const std::string command = argv[1];
  const std::vector<std::string> words(argv + 2, argv + argc);
  try {
    if (command == "render") return abcube::cmd_render(words);
    if (command == "compare") return abcube::cmd_compare(words);
    if (command == "info") return abcube::cmd_info(words);
    if (command == "export-pov") return abcube::cmd_export_pov(words);
    if (command == "crosscheck") return abcube::cmd_crosscheck(words);
    throw abcube::InputError("unknown command '" + command + "' (render, compare, info, export-pov, crosscheck)");
  } catch (const abcube::InputError& e) {
    std::fprintf(stderr, "abcube: %s\n", one_line(e.what()).c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "abcube: error: %s\n", one_line(e.what()).c_str());
    return 1;
  }
}
