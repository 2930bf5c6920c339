#include "io/image_module.hpp"

#include <dlfcn.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <mutex>

#include "base/error.hpp"

namespace abcube {

namespace {

namespace fs = std::filesystem;

constexpr const char* MODULE_FILE = "libabcube_oiio.so";
#ifndef ABCUBE_MODULE_LIBDIR
#define ABCUBE_MODULE_LIBDIR "lib/abcube"  // the install's library folder, relative to its prefix
#endif

std::atomic<const ImageModule*> loaded{nullptr};

// Where the module may be, in the order tried.
std::vector<std::string> candidates() {
  std::vector<std::string> out;
  // Set, it is the one place tried.
  if (const char* env = std::getenv("ABCUBE_IMAGE_MODULE"); env && *env) return {env};
  // The file holding this code: a shared library names itself; the main program may be
  // named only as it was started ("abcube"), so /proc/self/exe stands for it.
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&image_module_loaded), &info) && info.dli_fname) {
    std::error_code ec;
    const std::string name = info.dli_fname;
    fs::path self = name.find('/') != std::string::npos ? fs::canonical(name, ec) : fs::path();
    if (self.empty() || ec) {
      ec.clear();
      self = fs::canonical("/proc/self/exe", ec);
    }
    if (!ec) {
      // Beside it (the build tree's program, a pip-installed Python module), then
      // LIBDIR/abcube or abcube/ in the folders above it: bin/abcube of an installed prefix
      // finds lib/abcube; lib/python3/dist-packages/abcube*.so finds lib/abcube too.
      out.push_back((self.parent_path() / MODULE_FILE).string());
      fs::path up = self.parent_path();
      for (int level = 0; level < 3 && up.has_parent_path() && up != up.root_path(); ++level) {
        up = up.parent_path();
        out.push_back((up / ABCUBE_MODULE_LIBDIR / MODULE_FILE).string());
        out.push_back((up / "abcube" / MODULE_FILE).string());
      }
    }
  }
#ifdef ABCUBE_MODULE_BUILD_DIR
  out.push_back(std::string(ABCUBE_MODULE_BUILD_DIR) + "/" + MODULE_FILE);
#endif
#ifdef ABCUBE_MODULE_INSTALL_DIR
  out.push_back(std::string(ABCUBE_MODULE_INSTALL_DIR) + "/" + MODULE_FILE);
#endif
  return out;
}

}  // namespace

const ImageModule& image_module(const std::string& need) {
  if (const ImageModule* m = loaded.load(std::memory_order_acquire)) return *m;
  static std::mutex mutex;
  const std::lock_guard<std::mutex> lock(mutex);
  if (const ImageModule* m = loaded.load(std::memory_order_relaxed)) return *m;
  std::string tried;
  for (const std::string& path : candidates()) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
      tried += (tried.empty() ? "" : ", ") + path + " (absent)";
      continue;
    }
    // Never unloaded: its objects may live as long as the process.
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* e = dlerror();
      tried += (tried.empty() ? "" : ", ") + path + " (" + one_line(e ? e : "dlopen failed") + ")";
      continue;
    }
    using Entry = ImageModule* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, "abcube_image_module"));
    if (!entry) {
      tried += (tried.empty() ? "" : ", ") + path + " (no entry point abcube_image_module)";
      continue;
    }
    const ImageModule* m = entry();
    loaded.store(m, std::memory_order_release);
    return *m;
  }
  throw RuntimeFailure(need + " needs OpenImageIO, through abcube's image module " + MODULE_FILE +
                       ", which could not be loaded: " + tried + " (set ABCUBE_IMAGE_MODULE to its path)");
}

bool image_module_loaded() { return loaded.load(std::memory_order_acquire) != nullptr; }

}  // namespace abcube
