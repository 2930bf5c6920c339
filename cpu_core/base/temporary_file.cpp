#include "base/temporary_file.hpp"

#include <unistd.h>

#include <atomic>
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

}  // namespace

TemporaryFile::TemporaryFile(const std::string& final_path) : final_path_(final_path) {
  const std::filesystem::path p(final_path);
  path_ = (p.parent_path() / ("." + p.stem().string() + ".tmp" + std::to_string(getpid()) + p.extension().string()))
              .string();
  slot_ = publish(path_);
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
