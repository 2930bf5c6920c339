// The scene file's JSON: the document built with every syntax error's FILE:LINE:COL (from
// the parser's byte offset, as nori does), messages naming a value's path, and the typed
// readers of its values (scene_json.hpp).
#include "scene/scene_json.hpp"

#include <cctype>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "base/error.hpp"

namespace abcube::detail {

// ---- Messages ----------------------------------------------------------------------

// Shortest text that reads back as the same double.
std::string format_number(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[40];
  if (x == std::floor(x) && std::fabs(x) < 1e15) {  // integers as integers, not 2e+02
    std::snprintf(buf, sizeof buf, "%.0f", x);
    return buf;
  }
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

namespace {

constexpr size_t DESCRIBE_MAX_BYTES = 48;

// Appends v in compact JSON form (strings quoted by quote()), stopping once `out` is longer
// than DESCRIBE_MAX_BYTES: a value of megabytes costs no more than a short one.
void describe_into(const Json& v, std::string& out) {
  if (out.size() > DESCRIBE_MAX_BYTES) return;
  if (v.is_string()) {
    out += quote(v.get_ref<const std::string&>());
  } else if (v.is_array()) {
    out += '[';
    for (auto it = v.begin(); it != v.end() && out.size() <= DESCRIBE_MAX_BYTES; ++it) {
      if (it != v.begin()) out += ',';
      describe_into(*it, out);
    }
    out += ']';
  } else if (v.is_object()) {
    out += '{';
    for (auto it = v.begin(); it != v.end() && out.size() <= DESCRIBE_MAX_BYTES; ++it) {
      if (it != v.begin()) out += ',';
      out += quote(it.key()) + ':';
      describe_into(it.value(), out);
    }
    out += '}';
  } else {
    out += v.dump();  // a number, true, false, null
  }
}

}  // namespace

// A JSON value as it appears after "got" in a message, cut short when long.
std::string describe(const Json& v) {
  if (v.is_number()) return format_number(v.get<double>());
  std::string s;
  describe_into(v, s);
  if (s.size() > DESCRIBE_MAX_BYTES) {
    size_t cut = DESCRIBE_MAX_BYTES - 3;
    while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;  // not inside a character
    s = s.substr(0, cut) + "...";
  }
  return s;
}

std::string describe(const glm::dvec3& v) {
  return "[" + format_number(v.x) + ", " + format_number(v.y) + ", " + format_number(v.z) + "]";
}

// "parent.key", quoting keys that are not plain names (material names can be anything).
std::string member_path(const std::string& parent, const std::string& key) {
  bool plain = !key.empty() && key.size() <= QUOTE_MAX_CHARS;
  for (char c : key) plain = plain && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-');
  const std::string k = plain ? key : "[" + quote(key) + "]";
  if (parent.empty()) return k;
  return plain ? parent + "." + k : parent + k;
}

std::string index_path(const std::string& parent, size_t i) { return parent + "[" + std::to_string(i) + "]"; }

[[noreturn]] void fail(const Source& src, const std::string& path, const std::string& what) {
  throw InputError(one_line(path.empty() ? src.name + ": " + what : src.name + ": " + path + ": " + what));
}

// ---- JSON text -> document ---------------------------------------------------------

// Line and column (1-based, columns in UTF-8 code points) of byte `index` of `text`.
std::string line_column(const std::string& text, size_t index) {
  index = std::min(index, text.size());
  size_t line = 1, column = 1;
  for (size_t i = 0; i < index; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      ++line;
      column = 1;
    } else if ((c & 0xC0) != 0x80) {  // not a UTF-8 continuation byte
      ++column;
    }
  }
  return std::to_string(line) + ":" + std::to_string(column);
}

// nlohmann's message without its "[json.exception...] parse error at line L, column C:"
// prefix, which we replace by our own FILE:LINE:COL.
std::string parser_message(const std::string& what) {
  std::string m = what;
  if (!m.empty() && m[0] == '[') {
    const size_t end = m.find("] ");
    if (end != std::string::npos) m = m.substr(end + 2);
  }
  if (m.rfind("parse error", 0) == 0) {
    const size_t colon = m.find(": ");
    if (colon != std::string::npos) m = m.substr(colon + 2);
  }
  // The token nlohmann quotes ("...; last read: 'TOKEN'[; expected NAME]", "number overflow
  // parsing 'TOKEN'") can be a whole string or number of megabytes: cut short. The token
  // may hold anything, "'; expected " too (a fuzzed input did), so its end is found from
  // the message's end: the closing quote, or before "; expected " and one of the names
  // nlohmann gives a token type (lexer::token_type_name).
  static const char* const names[] = {"<uninitialized>",
                                      "true literal",
                                      "false literal",
                                      "null literal",
                                      "string literal",
                                      "number literal",
                                      "'['",
                                      "'{'",
                                      "']'",
                                      "'}'",
                                      "':'",
                                      "','",
                                      "<parse error>",
                                      "end of input",
                                      "'[', '{', or a literal",
                                      "unknown token"};
  auto ends_with = [&](const std::string& tail) {
    return m.size() >= tail.size() && m.compare(m.size() - tail.size(), tail.size(), tail) == 0;
  };
  for (const char* opener : {"; last read: '", "number overflow parsing '"}) {
    const size_t at = m.find(opener);
    if (at == std::string::npos) continue;
    const size_t from = at + std::strlen(opener);
    size_t to = std::string::npos;
    for (const char* name : names) {
      const std::string tail = std::string("'; expected ") + name;
      if (ends_with(tail)) to = m.size() - tail.size();
    }
    if (to == std::string::npos && ends_with("'")) to = m.size() - 1;
    if (to == std::string::npos || to < from) continue;
    m = m.substr(0, from) + printable(std::string_view(m).substr(from, to - from)) + m.substr(to);
  }
  if (m.rfind("number overflow", 0) == 0) m += " (numbers must be finite)";
  return m;
}

// Builds the document through the SAX interface so that a syntax error keeps its byte
// offset (numbers that overflow to infinity included) and a repeated key is caught with
// its path instead of silently replacing the first.
class DocumentBuilder final : public nlohmann::json_sax<Json> {
 public:
  Json root;
  std::string error_path, error_message;  // a repeated key
  bool syntax_error = false;
  size_t error_offset = 0;  // bytes read when the syntax error was found
  std::string error_token;  // the token that was read last

  bool null() override { return add(Json(nullptr)); }
  bool boolean(bool b) override { return add(Json(b)); }
  bool number_integer(number_integer_t v) override { return add(Json(v)); }
  bool number_unsigned(number_unsigned_t v) override { return add(Json(v)); }
  bool number_float(number_float_t v, const string_t&) override { return add(Json(v)); }
  bool string(string_t& s) override { return add(Json(std::move(s))); }
  bool binary(binary_t&) override { return add(Json(nullptr)); }  // not produced by JSON text
  bool start_object(std::size_t) override { return open(Json::object()); }
  bool start_array(std::size_t) override { return open(Json::array()); }
  bool end_object() override { return close(); }
  bool end_array() override { return close(); }

  bool key(string_t& k) override {
    Level& top = levels_.back();
    if (top.value->contains(k)) {
      error_path = member_path(path(), k);
      error_message = "field appears twice";
      return false;
    }
    top.key = k;
    return true;
  }

  bool parse_error(std::size_t position, const std::string& last_token,
                   const nlohmann::detail::exception& ex) override {
    syntax_error = true;
    error_offset = position;
    error_token = last_token;
    error_message = parser_message(ex.what());
    return false;
  }

 private:
  struct Level {
    Json* value;
    std::string key;  // the member being read, for objects
  };
  std::vector<Level> levels_;

  Json* place(Json v) {
    if (levels_.empty()) {
      root = std::move(v);
      return &root;
    }
    Level& top = levels_.back();
    if (top.value->is_array()) {
      top.value->push_back(std::move(v));
      return &top.value->back();
    }
    Json& slot = (*top.value)[top.key];
    slot = std::move(v);
    return &slot;
  }
  bool add(Json v) {
    place(std::move(v));
    return true;
  }
  bool open(Json v) {
    levels_.push_back({place(std::move(v)), {}});
    return true;
  }
  bool close() {
    levels_.pop_back();
    return true;
  }
  // Path of the innermost open container.
  std::string path() const {
    std::string p;
    for (size_t i = 1; i < levels_.size(); ++i) {
      const Level& parent = levels_[i - 1];
      p = parent.value->is_array() ? index_path(p, parent.value->size() - 1) : member_path(p, parent.key);
    }
    return p;
  }
};

// Byte offset of the first '[' or '{' that opens level MAX_JSON_DEPTH + 1 (strings
// skipped as JSON writes them), or npos. One pass over the bytes, no recursion: run before
// the parser so that no value of such a document is ever built.
size_t too_deep_at(const std::string& text) {
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;  // the escaped character, whatever it is
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > MAX_JSON_DEPTH) return i;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return std::string::npos;
}

Json parse_document(const std::string& text, const Source& src) {
  const size_t deep = too_deep_at(text);
  if (deep != std::string::npos) {
    throw InputError(one_line(src.name + ":" + line_column(text, deep) + ": arrays and objects nested deeper than " +
                              std::to_string(MAX_JSON_DEPTH) + " levels"));
  }
  DocumentBuilder builder;
  const bool ok = Json::sax_parse(text, &builder, Json::input_format_t::json, true, false);
  if (builder.syntax_error) {
    // Point at the last byte read or, when that ends one literal (a string without
    // blanks, a number, a word), at the literal's start. nlohmann's "last token" can
    // span several tokens, hence the check.
    const std::string& token = builder.error_token;
    const size_t end = builder.error_offset, n = token.size();
    size_t index = end > 0 ? end - 1 : 0;
    const bool one_literal = n > 1 && token.find_first_of(" \t\r\n,:{}[]") == std::string::npos;
    if (one_literal && n <= end && end <= text.size() && text.compare(end - n, n, token) == 0) index = end - n;
    throw InputError(one_line(src.name + ":" + line_column(text, index) + ": " + builder.error_message));
  }
  if (!builder.error_path.empty()) fail(src, builder.error_path, builder.error_message);
  if (!ok) throw InputError(one_line(src.name + ":1:1: cannot parse JSON"));
  return std::move(builder.root);
}

// ---- Typed values ------------------------------------------------------------------

double read_number(const Source& src, const Json& v, const std::string& path) {
  if (!v.is_number()) fail(src, path, "must be a number, got " + describe(v));
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail(src, path, "must be finite, got " + format_number(x));
  if (std::fabs(x) > FLT_MAX) {
    fail(src, path, "out of range (magnitude must be <= 3.4e38), got " + format_number(x));
  }
  return x;
}

int read_int(const Source& src, const Json& v, const std::string& path, int lo, int hi) {
  const double x = read_number(src, v, path);
  if (x != std::floor(x)) fail(src, path, "must be an integer, got " + format_number(x));
  if (x < lo) fail(src, path, "must be >= " + std::to_string(lo) + ", got " + format_number(x));
  if (x > hi) fail(src, path, "must be <= " + std::to_string(hi) + ", got " + format_number(x));
  return static_cast<int>(x);
}

glm::dvec3 read_vec3(const Source& src, const Json& v, const std::string& path) {
  if (!v.is_array() || v.size() != 3) fail(src, path, "must be an array of 3 numbers, got " + describe(v));
  glm::dvec3 r;
  for (int i = 0; i < 3; ++i)
    r[i] = read_number(src, v[static_cast<size_t>(i)], index_path(path, static_cast<size_t>(i)));
  return r;
}

std::string read_string(const Source& src, const Json& v, const std::string& path) {
  if (!v.is_string()) fail(src, path, "must be a string, got " + describe(v));
  return v.get<std::string>();
}

bool read_bool(const Source& src, const Json& v, const std::string& path) {
  if (!v.is_boolean()) fail(src, path, "must be true or false, got " + describe(v));
  return v.get<bool>();
}

void check_range(const Source& src, const std::string& path, double x, double lo, double hi) {
  if (x < lo || x > hi) {
    fail(src, path, "must be in [" + format_number(lo) + ", " + format_number(hi) + "], got " + format_number(x));
  }
}

void check_non_negative(const Source& src, const std::string& path, const glm::dvec3& v) {
  for (int i = 0; i < 3; ++i) {
    if (v[i] < 0) fail(src, index_path(path, static_cast<size_t>(i)), "must be >= 0, got " + format_number(v[i]));
  }
}

}  // namespace abcube::detail
