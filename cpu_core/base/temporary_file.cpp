#include "base/temporary_file.hpp"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "base/error.hpp"
#include "base/parallel.hpp"

namespace abcube {

namespace {

// The paths a signal handler may remove: a slot is taken (busy), filled, then published
// (ready); the handler reads only published slots. Sixteen writes at once is more than any
// caller makes (one per output of a render); past that a temporary is still removed by its
// destructor, only not by the handler.
constexpr int SLOTS = 16;
constexpr size_t PATH_BYTES = 4096;
struct Slot {
  std::atomic<bool> busy{false};
  std::atomic<bool> ready{false};
  char path[PATH_BYTES] = {};
};
Slot slots[SLOTS];

int publish(const std::string& path) {
  if (path.size() >= PATH_BYTES) return -1;
  for (int i = 0; i < SLOTS; ++i) {
    bool expected = false;
    if (slots[i].busy.compare_exchange_strong(expected, true)) {
      std::memcpy(slots[i].path, path.c_str(), path.size() + 1);
      slots[i].ready.store(true, std::memory_order_release);
      return i;
    }
  }
  return -1;
}

void withdraw(int slot) {
  if (slot < 0) return;
  slots[slot].ready.store(false, std::memory_order_release);
  slots[slot].busy.store(false, std::memory_order_release);
}

// This host's name as temporaries carry it: letters, digits, '-' and '_', at most 32.
const std::string& host_tag() {
  static const std::string tag = [] {
    char name[256] = {};
    if (gethostname(name, sizeof name - 1) != 0) return std::string("host");
    std::string t;
    for (const char* c = name; *c && t.size() < 32; ++c) {
      if (std::isalnum(static_cast<unsigned char>(*c)) || *c == '-' || *c == '_') t += *c;
    }
    return t.empty() ? std::string("host") : t;
  }();
  return tag;
}

// The process id of a temporary of this host: NAME ".STEM.tmpPID-HOST" then, optionally,
// ".EXT"; 0 when the name is no such temporary.
pid_t temporary_writer(const std::string& name) {
  if (name.size() < 2 || name[0] != '.') return 0;
  const std::string mark = "-" + host_tag();
  for (size_t at = name.find(".tmp", 1); at != std::string::npos; at = name.find(".tmp", at + 1)) {
    size_t i = at + 4, digits = 0;
    long long pid = 0;
    while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i])) && digits < 10) {
      pid = pid * 10 + (name[i++] - '0');
      ++digits;
    }
    if (digits == 0 || name.compare(i, mark.size(), mark) != 0) continue;
    const size_t end = i + mark.size();
    if (end == name.size() || (name[end] == '.' && name.find('.', end + 1) == std::string::npos)) {
      return static_cast<pid_t>(pid);
    }
  }
  return 0;
}

}  // namespace

TemporaryFile::TemporaryFile(const std::string& final_path) : final_path_(final_path) {
  const std::filesystem::path p(final_path);
  path_ = (p.parent_path() /
           ("." + p.stem().string() + ".tmp" + std::to_string(getpid()) + "-" + host_tag() + p.extension().string()))
              .string();
  slot_ = publish(path_);
}

size_t remove_stale_temporaries(const std::string& folder) {
  std::error_code ec;
  size_t removed = 0;
  for (std::filesystem::directory_iterator it(folder.empty() ? "." : folder, ec), end; !ec && it != end;
       it.increment(ec)) {
    const pid_t pid = temporary_writer(it->path().filename().string());
    if (pid <= 0 || pid == getpid()) continue;
    if (kill(pid, 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to judge
    std::error_code gone;
    if (std::filesystem::remove(it->path(), gone)) ++removed;
  }
  return removed;
}

TemporaryFile::~TemporaryFile() {
  if (!committed_) std::remove(path_.c_str());
  withdraw(slot_);
}

void TemporaryFile::commit() {
  check_stop_request();  // the destructor removes the temporary
  if (std::rename(path_.c_str(), final_path_.c_str()) != 0) {
    throw RuntimeFailure(final_path_ + ": cannot write: " + std::strerror(errno));
  }
  committed_ = true;
}

void remove_temporary_files_now() {
  for (Slot& s : slots) {
    if (s.ready.load(std::memory_order_acquire)) unlink(s.path);
  }
}

}  // namespace abcube
