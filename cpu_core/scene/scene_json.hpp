// Internal to scene loading (scene_load.hpp): the JSON document with the place of every
// value, messages that name that place, and the typed readers of its fields.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "base/nearest_name.hpp"

namespace abcube::detail {

using Json = nlohmann::ordered_json;  // keeps the file's order: materials are numbered as written

// Where the messages point: the scene as named by the caller, and the folder mesh paths
// are relative to.
struct Source {
  std::string name;
  std::string base_dir;
};

// ---- Messages ----------------------------------------------------------------------

// Messages quote input through base/error.hpp (quote, printable, one_line).
// Shortest text that reads back as the same double.
std::string format_number(double x);
// A JSON value as it appears after "got" in a message: strings quoted, arrays and objects
// cut short after about 48 characters (only what is shown is visited).
std::string describe(const Json& v);
std::string describe(const glm::dvec3& v);
// "parent.key", or parent["key"] with the key quoted when it is not a short plain name
// (material names can be anything).
std::string member_path(const std::string& parent, const std::string& key);
std::string index_path(const std::string& parent, size_t i);
// Throws InputError "NAME: PATH: WHAT" (one line).
[[noreturn]] void fail(const Source& src, const std::string& path, const std::string& what);

// ---- JSON text -> document ---------------------------------------------------------

// Arrays and objects nested deeper than this are refused before any value is built (a
// scene needs 5 levels; nlohmann's serializer and our readers recurse once per level).
constexpr int MAX_JSON_DEPTH = 64;

// The document of `text`; a syntax error, nesting deeper than MAX_JSON_DEPTH or a repeated
// key throws InputError naming FILE:LINE:COL or the key's path.
Json parse_document(const std::string& text, const Source& src);

// ---- Typed values ------------------------------------------------------------------

double read_number(const Source& src, const Json& v, const std::string& path);
int read_int(const Source& src, const Json& v, const std::string& path, int lo, int hi);
glm::dvec3 read_vec3(const Source& src, const Json& v, const std::string& path);
std::string read_string(const Source& src, const Json& v, const std::string& path);
bool read_bool(const Source& src, const Json& v, const std::string& path);
void check_range(const Source& src, const std::string& path, double x, double lo, double hi);
void check_non_negative(const Source& src, const std::string& path, const glm::dvec3& v);

// One JSON object being read. Unknown members are rejected up front, before any value
// is read (pbrt-v4 and Mitsuba 3 reject unused parameters), so a typo is reported as
// itself rather than as the missing field it was meant to be.
class Fields {
 public:
  Fields(const Source& src, const Json& j, std::string path, const std::vector<const char*>& known)
      : src_(src), j_(j), path_(std::move(path)) {
    if (!j.is_object()) fail(src, path_, "must be an object, got " + describe(j));
    for (const auto& member : j.items()) {
      bool found = false;
      for (const char* k : known) found = found || member.key() == k;
      if (found) continue;
      std::string list;
      for (const char* k : known) list += std::string(list.empty() ? "" : ", ") + k;
      fail(src, member_path(path_, member.key()),
           "unknown field (known here: " + list + ")" + did_you_mean(member.key(), {known.begin(), known.end()}));
    }
  }

  const Source& src() const { return src_; }
  const std::string& path() const { return path_; }
  std::string at(const char* key) const { return member_path(path_, key); }
  const Json* find(const char* key) const {
    const auto it = j_.find(key);
    return it == j_.end() ? nullptr : &*it;
  }
  const Json& need(const char* key) const {
    const Json* v = find(key);
    if (!v) fail(src_, at(key), "missing required field");
    return *v;
  }

  double number(const char* key) const { return read_number(src_, need(key), at(key)); }
  double number(const char* key, double fallback) const {
    const Json* v = find(key);
    return v ? read_number(src_, *v, at(key)) : fallback;
  }
  glm::dvec3 vec3(const char* key) const { return read_vec3(src_, need(key), at(key)); }
  glm::dvec3 vec3(const char* key, const glm::dvec3& fallback) const {
    const Json* v = find(key);
    return v ? read_vec3(src_, *v, at(key)) : fallback;
  }
  int integer(const char* key, int fallback, int lo, int hi) const {
    const Json* v = find(key);
    return v ? read_int(src_, *v, at(key), lo, hi) : fallback;
  }
  // A number in [lo, hi], or the fallback when absent.
  double number_in(const char* key, double fallback, double lo, double hi) const {
    const double x = number(key, fallback);
    check_range(src_, at(key), x, lo, hi);
    return x;
  }

 private:
  const Source& src_;
  const Json& j_;
  std::string path_;
};

}  // namespace abcube::detail
