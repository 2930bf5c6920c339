// A render method is one unit: a RenderMethod that says which options it reads, whether it
// draws with GL, what its render costs in memory, and renders. The Renderer knows no method
// by name: it looks the name up in the registry and calls the unit. Adding a method is one
// file with its RenderMethod and one register_method line (the built-ins' are in
// method_registry.cpp); docs/design/overview.md says how.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <abcube/image.hpp>
#include <abcube/render_options.hpp>

#include "render/method_context.hpp"

namespace abcube {

class RenderMethod {
 public:
  virtual ~RenderMethod() = default;
  // The name every door takes: --method, render.method, method=. Lower case, digits, '_'.
  virtual std::string name() const = 0;
  // One line for the help and the docs.
  virtual std::string summary() const = 0;
  // The method-specific options (the table's keys whose spec has per_method) it reads. Any
  // other one given with this method is refused, naming the methods that read it.
  virtual std::vector<std::string> reads() const = 0;
  // What it reads of `options` into `request`: the options struct of its own passes
  // (request->map, request->gpu). Called after the option table has checked every value;
  // `view` is the scene with the render's overrides.
  virtual void read_options(const RenderOptions& options, const SceneData& view, RenderRequest* request) const {
    (void)options;
    (void)view;
    (void)request;
  }
  // Draws with GL: the Renderer opens GL and uploads the scene (mc.gl_scene) first.
  virtual bool needs_gl() const { return false; }
  // Bytes the render needs besides its A-buffers' fragments (which are counted as they are
  // built), checked against the budget before any pass.
  virtual uint64_t render_bytes(const SceneData& scene) const;
  // The image. Its passes write their figures into mc.stats ("plan" and the method's own
  // sections), and their timings and the GL path they drew with into mc.record.
  virtual Image render(MethodContext& mc) const = 0;
};

// Adds `method` to the registry; InputError when its name is taken or malformed, or when it
// reads an option the table does not mark per-method (thrown from a static initializer, that
// ends the program before main). The registry is process-wide; register before the first
// render (at start or in a static initializer). Returns true, so that a unit can register
// itself with
//   const bool registered = abcube::register_method(std::make_unique<MyMethod>());
bool register_method(std::unique_ptr<RenderMethod> method);

// Every registered method: the built-ins in their order, then the others in the order they
// were registered.
const std::vector<const RenderMethod*>& registered_methods();

// The method named `name`; OptionError for "method" naming the registered ones otherwise.
const RenderMethod& method_named(const std::string& name);

}  // namespace abcube
