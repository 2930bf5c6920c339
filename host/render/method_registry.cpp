// The registry of render methods (method.hpp) and what the doors ask of it: the names,
// which methods read an option, and the refusal of an option the chosen method does not read.
#include <algorithm>
#include <mutex>

#include <abcube/options.hpp>
#include <abcube/renderer.hpp>

#include "base/error.hpp"
#include "render/method.hpp"
#include "scene/scene_load.hpp"

namespace abcube {

// The built-in units (render/methods/).
std::unique_ptr<RenderMethod> make_map_method(MapVariant variant);
std::unique_ptr<RenderMethod> make_raytrace_method();
std::unique_ptr<RenderMethod> make_gpu_method();
std::unique_ptr<RenderMethod> make_hybrid_method();
std::unique_ptr<RenderMethod> make_gpu_abuffer_method();

namespace {

struct Registry {
  std::mutex mutex;  // registrations; lookups read a list that only grows before renders
  std::vector<std::unique_ptr<RenderMethod>> owned;
  std::vector<const RenderMethod*> methods;
};

void add(Registry& r, std::unique_ptr<RenderMethod> method) {
  const std::string name = method->name();
  if (name.empty() || name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") != std::string::npos) {
    throw InputError("register_method: a method's name is lower-case letters, digits and '_', got " + quote(name));
  }
  for (const RenderMethod* m : r.methods) {
    if (m->name() == name) throw InputError("register_method: a method named " + quote(name) + " is registered");
  }
  for (const std::string& key : method->reads()) {
    const OptionSpec* spec = find_render_option(key);
    if (!spec || spec->key != key || !spec->per_method) {
      throw InputError("register_method: method " + name + " reads " + quote(key) +
                       ", which is no per-method option of the table");
    }
  }
  r.methods.push_back(method.get());
  r.owned.push_back(std::move(method));
}

Registry& registry() {
  static Registry r;
  static const bool built_in = [] {
    // The built-ins, in the order the help lists them: one line a method.
    add(r, make_map_method(MapVariant::abuffer));
    add(r, make_map_method(MapVariant::zbuffer));
    add(r, make_map_method(MapVariant::envmap));
    add(r, make_raytrace_method());
    add(r, make_gpu_method());
    add(r, make_hybrid_method());
    add(r, make_gpu_abuffer_method());
    return true;
  }();
  (void)built_in;
  return r;
}

bool reads(const RenderMethod& m, const std::string& key) {
  const std::vector<std::string> keys = m.reads();
  return std::find(keys.begin(), keys.end(), key) != keys.end();
}

}  // namespace

uint64_t RenderMethod::render_bytes(const SceneData& scene) const { return estimate_render_bytes(scene, needs_gl()); }

bool register_method(std::unique_ptr<RenderMethod> method) {
  ABCUBE_CHECK(method != nullptr, "register_method: no method");
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  add(r, std::move(method));
  return true;
}

const std::vector<const RenderMethod*>& registered_methods() { return registry().methods; }

const RenderMethod& method_named(const std::string& name) {
  for (const RenderMethod* m : registered_methods()) {
    if (m->name() == name) return *m;
  }
  const std::vector<std::string> names = method_names();
  throw OptionError("method",
                    "must be one of " + join(names, ", ") + ", got " + quote(name) + did_you_mean(name, names));
}

std::vector<std::string> method_names() {
  std::vector<std::string> names;
  for (const RenderMethod* m : registered_methods()) names.push_back(m->name());
  return names;
}

std::vector<std::string> methods_reading(const std::string& key) {
  std::vector<std::string> names;
  const OptionSpec* spec = find_render_option(key);
  if (!spec || !spec->per_method) return names;
  for (const RenderMethod* m : registered_methods()) {
    if (reads(*m, spec->key)) names.push_back(m->name());
  }
  return names;
}

void refuse_options_unused_by(const std::string& scene_method, const RenderOptions& options) {
  check_render_options(options);
  const RenderMethod& method = method_named(options.method.empty() ? scene_method : options.method);
  for (const std::string& key : given_render_options(options)) {
    if (!find_render_option(key)->per_method || reads(method, key)) continue;
    const std::vector<std::string> readers = methods_reading(key);
    throw OptionError(
        key, "not used by method " + method.name() + " (" +
                 (readers.empty() ? std::string("no method reads it") : "read by " + join(readers, ", ")) + ")");
  }
  // The GPU's searches answer from candidates by the crossing mode's choice alone.
  if (reads(method, "search_on") && options.search_on == "gpu" && options.search != "crossing") {
    throw OptionError("search_on", "gpu takes the crossing mode only (search crossing), got search " + options.search);
  }
}

RenderOptions without_unused_options(const RenderOptions& options, const std::string& method_name) {
  const RenderMethod& method = method_named(method_name);
  RenderOptions out = options;
  out.method = method_name;
  for (const OptionSpec& spec : render_option_table()) {
    if (spec.per_method && !reads(method, spec.key)) reset_render_option(out, spec.key);
  }
  return out;
}

}  // namespace abcube
