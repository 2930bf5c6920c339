#include "base/error.hpp"

#include <cstdint>
#include <cstdio>
#include <utility>

namespace abcube {

void check_failed(const char* expr, const char* file, int line, const std::string& detail) {
  throw InternalError(std::string("internal check failed: ") + expr + " at " + file + ":" + std::to_string(line) +
                      ": " + detail);
}

namespace {

// Length of the valid UTF-8 sequence at text[i] that is not a C1 control, or 0.
size_t utf8_printable_length(std::string_view text, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = byte(i);
  size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // allowed range of the second byte
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2;
    if (c == 0xC2) lo = 0xA0;  // U+0080..U+009F are the C1 controls
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    if (c == 0xE0) lo = 0xA0;  // overlong
    if (c == 0xED) hi = 0x9F;  // surrogates
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    if (c == 0xF0) lo = 0x90;  // overlong
    if (c == 0xF4) hi = 0x8F;  // above U+10FFFF
  } else {
    return 0;
  }
  if (i + n > text.size() || byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (size_t k = 2; k < n; ++k) {
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  }
  return n;
}

void append_hex(std::string& out, unsigned char c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "\\x%02X", c);
  out += buf;
}

// The character at text[i] escaped onto `out` (ASCII controls by name or \xNN, invalid
// UTF-8 and C1 controls byte by byte); returns the bytes it took. With `quoted`, quotes
// and backslashes are escaped too.
size_t append_escaped(std::string& out, std::string_view text, size_t i, bool quoted) {
  const unsigned char c = static_cast<unsigned char>(text[i]);
  if (c < 0x80) {
    switch (c) {
      case 0x1B: out += "\\e"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      case '"': out += quoted ? "\\\"" : "\""; break;
      case '\\': out += quoted ? "\\\\" : "\\"; break;
      default:
        if (c < 0x20 || c == 0x7F) {
          append_hex(out, c);
        } else {
          out += static_cast<char>(c);
        }
    }
    return 1;
  }
  const size_t n = utf8_printable_length(text, i);
  if (n == 0) {
    append_hex(out, c);
    return 1;
  }
  out.append(text.substr(i, n));
  return n;
}

// The first `max_chars` characters of `text` escaped, in at most `max_bytes` bytes (a cut
// never splits a character or an escape), and how many bytes of `text` they took.
std::pair<std::string, size_t> escape_prefix(std::string_view text, size_t max_chars, bool quoted,
                                             size_t max_bytes = SIZE_MAX) {
  std::string out;
  size_t shown = 0;
  for (size_t chars = 0; shown < text.size() && chars < max_chars; ++chars) {
    const size_t before = out.size();
    const size_t took = append_escaped(out, text, shown, quoted);
    if (out.size() > max_bytes) {
      out.resize(before);
      break;
    }
    shown += took;
  }
  return {out, shown};
}

// What follows a piece of input that was cut.
std::string length_note(std::string_view text) { return "... (" + std::to_string(text.size()) + " bytes)"; }

}  // namespace

std::string printable(std::string_view text, size_t max_chars) {
  const auto [body, shown] = escape_prefix(text, max_chars, false);
  return shown < text.size() ? body + length_note(text) : body;
}

std::string quote(std::string_view text, size_t max_chars, size_t max_bytes) {
  const auto [body, shown] = escape_prefix(text, max_chars, true, max_bytes);
  return "\"" + body + "\"" + (shown < text.size() ? length_note(text) : "");
}

std::string one_line(std::string_view text, const char* line_break) {
  while (!text.empty() && (text.back() == ' ' || text.back() == '\n' || text.back() == '\r' || text.back() == '\t')) {
    text.remove_suffix(1);
  }
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') {
      ++i;  // CR LF is one line break
    } else if (c == '\n' || c == '\r') {
      out += line_break;
      ++i;
    } else if (c == '\t') {
      out += ' ';
      ++i;
    } else {
      i += append_escaped(out, text, i, false);
    }
  }
  return out;
}

}  // namespace abcube
