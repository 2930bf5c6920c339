#include "base/input_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "base/error.hpp"

namespace abcube {

namespace fs = std::filesystem;

std::string format_bytes(uint64_t bytes) {
  constexpr uint64_t KIB = 1024, MIB = KIB * 1024, GIB = MIB * 1024;
  const auto in = [&](uint64_t unit, const char* name) {
    char buf[48];
    if (bytes % unit == 0) {
      std::snprintf(buf, sizeof buf, "%llu %s", static_cast<unsigned long long>(bytes / unit), name);
    } else {
      std::snprintf(buf, sizeof buf, "%.1f %s", static_cast<double>(bytes) / static_cast<double>(unit), name);
    }
    return std::string(buf);
  };
  if (bytes >= GIB) return in(GIB, "GiB");
  if (bytes >= MIB) return in(MIB, "MiB");
  if (bytes >= KIB) return in(KIB, "KiB");
  return std::to_string(bytes) + " bytes";
}

std::string input_file_problem(const std::string& path, uint64_t max_bytes) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (status.type() == fs::file_type::not_found) return "no such file";
  if (ec) return ec.message();
  switch (status.type()) {
    case fs::file_type::regular: break;
    case fs::file_type::directory: return "is a directory";
    case fs::file_type::character: return "not a regular file (a character device)";
    case fs::file_type::block: return "not a regular file (a block device)";
    case fs::file_type::fifo: return "not a regular file (a named pipe)";
    case fs::file_type::socket: return "not a regular file (a socket)";
    default: return "not a regular file";
  }
  const uint64_t size = fs::file_size(path, ec);
  if (ec) return ec.message();
  if (size > max_bytes) return "is " + format_bytes(size) + ", over the cap of " + format_bytes(max_bytes);
  return "";
}

std::string read_input_file(const std::string& path, uint64_t max_bytes, const std::string& what) {
  const auto refuse = [&](const std::string& why) {
    throw InputError(one_line(path + ": cannot read " + what + ": " + why));
  };
  const std::string problem = input_file_problem(path, max_bytes);
  if (!problem.empty()) refuse(problem);
  std::ifstream in(path, std::ios::binary);
  if (!in) refuse(std::strerror(errno));
  std::string text;
  char buffer[1 << 16];
  while (in) {
    in.read(buffer, sizeof buffer);
    text.append(buffer, static_cast<size_t>(in.gcount()));
    if (text.size() > max_bytes) refuse("grew over the cap of " + format_bytes(max_bytes) + " while read");
  }
  if (in.bad()) refuse("read error");
  return text;
}

}  // namespace abcube
