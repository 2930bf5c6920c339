// Errors that carry where they came from (pbrt-v4 FileLoc style), and the one place where
// text from the input is put into a message (quote, printable, one_line).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>
#include <string_view>

#include <abcube/error.hpp>  // InputError, RuntimeFailure, InternalError

namespace abcube {

// Always-on invariant check that names its operands (pbrt-v4 CHECK); throws InternalError.
[[noreturn]] void check_failed(const char* expr, const char* file, int line, const std::string& detail);

// ---- Input text in messages -----------------------------------------------------------
// A name, a path or a value read from a file can hold anything: megabytes, line breaks,
// terminal escape sequences. Every message shows it through these, so that an error is
// one short line that is safe to print on a terminal.

// Characters of one piece of input a message shows; the rest is cut.
constexpr size_t QUOTE_MAX_CHARS = 80;

// `text` as it may appear in a message: control bytes as \e (ESC), \n, \r, \t or \xNN; a
// byte that is not part of valid UTF-8, and the C1 controls U+0080..U+009F, as \xNN each;
// after `max_chars` characters the rest is cut and "... (N bytes)" gives the full length.
std::string printable(std::string_view text, size_t max_chars = QUOTE_MAX_CHARS);

// How every message quotes input: printable(text) between double quotes, quotes and
// backslashes escaped as \" and \\, e.g. "my \"glass\"", "\e]0;title\x07", "aaaa"... (200000 bytes).
// `max_bytes` also caps the bytes between the quotes (an escaped byte takes four: \xNN).
std::string quote(std::string_view text, size_t max_chars = QUOTE_MAX_CHARS, size_t max_bytes = SIZE_MAX);

// Paths are quoted whole up to this many bytes as shown, escapes included (real paths are
// shorter; a "file" field of megabytes, or a name of control bytes, is still cut), so that
// a message naming two or three paths stays under 4 KiB.
constexpr size_t QUOTE_PATH_MAX_BYTES = 1024;
inline std::string quote_path(std::string_view path) { return quote(path, QUOTE_PATH_MAX_BYTES, QUOTE_PATH_MAX_BYTES); }

// A message made one line and safe for a terminal: each line break becomes `line_break`,
// a tab a blank, every other control byte is escaped as by printable (nothing is cut), and
// trailing blanks are dropped.
std::string one_line(std::string_view text, const char* line_break = " ");

// The names with `separator` between them ("abuffer, zbuffer, ...").
inline std::string join(const std::vector<std::string>& names, const char* separator) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : separator) + n;
  return out;
}

}  // namespace abcube

#define ABCUBE_CHECK(cond, detail)                                            \
  do {                                                                        \
    if (!(cond)) ::abcube::check_failed(#cond, __FILE__, __LINE__, (detail)); \
  } while (0)
