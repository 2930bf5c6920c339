// abcube: a headless hybrid renderer (docs/cli.md).
#include "cli/cli_main.hpp"

int main(int argc, char** argv) { return abcube::cli_main(argc, argv); }
