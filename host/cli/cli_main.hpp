// The abcube program as a function: main.cpp calls it, and so does a program that links
// the library with methods of its own (tests/methods): every command, with the methods
// registered before it is called.
#pragma once

namespace abcube {

// Parses the command line and runs the command; returns the exit status (docs/cli.md).
int cli_main(int argc, char** argv);

}  // namespace abcube
