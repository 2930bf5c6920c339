// Input files (scenes, meshes, MTL files): refused at once when they are not regular files
// (a directory, /dev/zero, a named pipe) or when they are larger than their kind's cap, so
// that reading one can never run the machine out of memory or block forever.
#pragma once
#include <cstdint>
#include <string>

namespace abcube {

// Why `path` cannot be read as an input file of at most `max_bytes` bytes (symbolic links
// followed), or "" when it can: "no such file", "is a directory", "not a regular file (a
// character device)", "is 9.0 GiB, over the cap of 8 GiB", ...
std::string input_file_problem(const std::string& path, uint64_t max_bytes);

// The whole of the regular file `path`, at most `max_bytes` bytes (never more than that is
// read, should the file grow meanwhile). InputError "PATH: cannot read WHAT: why" otherwise.
std::string read_input_file(const std::string& path, uint64_t max_bytes, const std::string& what);

// "512 bytes", "64 MiB", "9.5 GiB": a size in a message.
std::string format_bytes(uint64_t bytes);

}  // namespace abcube
