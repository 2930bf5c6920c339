// abcube: headless hybrid renderer. Subcommands: render, compare, info (../shared/cli.md).
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "error.hpp"

namespace {

const char* USAGE =
    "usage: abcube render SCENE.json -o OUT.png [--method abuffer|zbuffer|envmap|raytrace|gpu]\n"
    "                     [--cube-res N] [--max-depth D] [--threads K] [--gl auto|egl|egl-device|\n"
    "                     egl-surfaceless|osmesa|none] [--gl-device K] [--stats STATS.json] [--reference]\n"
    "       abcube compare A.png B.png [--diff HEAT.png] [--fail T] [--failpercent P]\n"
    "       abcube info\n"
    "       abcube export-pov SCENE.json -o OUT.pov\n";

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    std::fputs(USAGE, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  const std::string command = argv[1];
  const std::vector<std::string> words(argv + 2, argv + argc);
  try {
    if (command == "render") return abcube::cmd_render(words);
    if (command == "compare") return abcube::cmd_compare(words);
    if (command == "info") return abcube::cmd_info(words);
    if (command == "export-pov") return abcube::cmd_export_pov(words);
    throw abcube::InputError("unknown command '" + command + "' (render, compare, info, export-pov)");
  } catch (const abcube::InputError& e) {
    std::string line = e.what();
    for (char& c : line) c = c == '\n' ? ' ' : c;
    std::fprintf(stderr, "abcube: %s\n", line.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "abcube: error: %s\n", e.what());
    return 1;
  }
}
