// The render options, in one table. The command line's flags (`abcube render`, `abcube
// batch`), the batch jobs' keys, the Python keywords, their validation and their help are
// all read from it, so that every door takes the same options with the same checks and the
// same messages. Which method reads a per-method option is the method's to say: its unit
// lists the keys it reads (<abcube/renderer.hpp> methods_reading).
//
//   #include <abcube/options.hpp>
//   #include <abcube/renderer.hpp>  // Scene, Renderer, refuse_unused_options
//
//   abcube::RenderSetup setup;
//   abcube::set_render_option(setup, "cube_res", "256");            // JSON text
//   abcube::set_render_option_text(setup, "--camera-position", "0,1,2");  // as typed
//   abcube::Scene scene = abcube::Scene::load(path, setup.limits, setup.set);
//   abcube::refuse_unused_options(scene, setup.render);
//   abcube::Renderer(setup.renderer).render(scene, setup.render);
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <abcube/error.hpp>
#include <abcube/render_options.hpp>
#include <abcube/scene_limits.hpp>

namespace abcube {

// What one render is set up with: each option writes one of these.
struct RenderSetup {
  RenderOptions render;
  RendererOptions renderer;
  SceneLimits limits;
  SceneOverrides set;  // scene values replaced before the scene is read (--set KEY=VALUE)
};

enum class OptionKind {
  choice,   // one of `choices`
  integer,  // a whole number in [min, max]
  number,   // a finite number in [min, max]
  flag,     // true or false (on the command line: given or not)
  path,     // a file's path
  text,     // a string of the form the help gives (--size: WxH)
  vec3,     // 3 finite numbers ("X,Y,Z" on the command line)
  names,    // a list of `choices` ("a,b" on the command line)
  setting,  // a scene value replaced: KEY=VALUE (batch and Python: an object {KEY: VALUE})
  method,   // a render method's name (<abcube/renderer.hpp> method_names: the registered ones)
};

// Where an option can be given. Every option is a command-line flag of `abcube render`.
enum class OptionScope {
  job,      // any render: a flag of render and batch, a batch job key, a Python keyword
  process,  // one per process: render's and batch's command line; Python: Renderer()
  scene,    // how scenes are loaded: the command line; Python: load_scene()
};

struct OptionSpec {
  std::string key;   // batch job key and Python keyword: "cube_res"
  std::string flag;  // command line: "--cube-res"
  OptionKind kind;
  OptionScope scope;
  std::vector<std::string> choices;  // choice and names: the values taken
  double min = 0, max = 0;           // integer and number: the range, both ends in
  std::string default_text;          // what an option not given means
  std::string unit;                  // "texels", "degrees", "MiB", ... or ""
  // Read only by the methods that list it (RenderMethod::reads); given with another
  // method, the render is refused (refuse_unused_options). False: every method reads it.
  bool per_method = false;
  std::string help;
  std::vector<std::string> aliases;  // other keys taken for it (older Python keywords)
};

// Every option, in the order --help lists them.
const std::vector<OptionSpec>& render_option_table();

// The option whose key, alias or flag is `name`; null when none is.
const OptionSpec* find_render_option(const std::string& name);

// Every key and flag, for "did you mean ...?" after an unknown one.
std::vector<std::string> render_option_names();

// "; did you mean NAME?" for the name of `known` nearest `given` (a typo's fix), or "".
std::string did_you_mean(const std::string& given, const std::vector<std::string>& known);

// Bad value of one option: `key` is the option's key (its flag on the command line is
// find_render_option(key)->flag), `reason` the rest of the message, the same whichever way
// the option came. what() is "KEY: REASON".
struct OptionError : InputError {
  OptionError(std::string key_, std::string reason_)
      : InputError(key_ + ": " + reason_), key(std::move(key_)), reason(std::move(reason_)) {}
  std::string key, reason;
};

// Sets the option named `name` (key, alias or flag) from `json_value`, JSON text as a
// batch job holds it ("256", "\"thesis\"", "[0, 1, 2]", "true"). Validated here, once for
// every door: OptionError for a bad value; InputError for an unknown name, suggesting the
// nearest. A setting option takes an object {"KEY": VALUE, ...}, each VALUE any JSON.
void set_render_option(RenderSetup& setup, const std::string& name, const std::string& json_value);

// The same from the command line's text: "256", "thesis", "0,1,2" (vec3, names),
// "KEY=VALUE" (a setting: VALUE read as JSON, else as a string); a flag takes "true" or
// "false" (the flag given alone is "true").
void set_render_option_text(RenderSetup& setup, const std::string& name, const std::string& text);

// Every option of `options` checked as set_render_option checks it (the library's own
// guard for options set in C++): OptionError for the first bad one. Renderer::render calls it.
void check_render_options(const RenderOptions& options);

// The keys of the job options `options` gives: those whose value is not the default.
std::vector<std::string> given_render_options(const RenderOptions& options);

// A per-method option set back to its default in `options` (InternalError for an option
// every method reads). <abcube/renderer.hpp> without_unused_options does it for a method.
void reset_render_option(RenderOptions& options, const std::string& key);

}  // namespace abcube
