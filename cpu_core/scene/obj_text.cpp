// THE GRAMMAR and PARALLEL READING: obj_text.hpp.
#include "scene/obj_text.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "base/error.hpp"
#include "base/parallel.hpp"

namespace abcube {

namespace {

bool blank(char c) { return c == ' ' || c == '\t'; }

const char* skip_blanks(const char* p, const char* e) {
  while (p < e && blank(*p)) ++p;
  return p;
}

// The end of the word at p: the next blank or '\r' (tinyobjloader's " \t\r").
const char* word_end(const char* p, const char* e) {
  while (p < e && !blank(*p) && *p != '\r') ++p;
  return p;
}

bool digit(char c) { return c >= '0' && c <= '9'; }

// A number of THE GRAMMAR at the start of [p, e), or `otherwise`.
float number(const char* p, const char* e, float otherwise) {
  const char* q = p;
  bool negative = false;
  if (q < e && (*q == '+' || *q == '-')) negative = *q++ == '-';
  const char* mantissa = q;
  const char* digits = q;
  while (q < e && digit(*q)) ++q;
  size_t count = static_cast<size_t>(q - digits);
  if (q < e && *q == '.') {
    digits = ++q;
    while (q < e && digit(*q)) ++q;
    count += static_cast<size_t>(q - digits);
  }
  if (count == 0) return otherwise;
  if (q < e && (*q == 'e' || *q == 'E')) {
    ++q;
    if (q < e && (*q == '+' || *q == '-')) ++q;
    const char* exponent = q;
    while (q < e && digit(*q)) ++q;
    if (q == exponent) return otherwise;  // "1e": no number (as tinyobjloader)
  }
  float f = 0.0f;
  const std::from_chars_result r = std::from_chars(mantissa, q, f, std::chars_format::general);
  if (r.ec == std::errc::result_out_of_range) {
    // Past float's range either way: strtof says which (inf or a zero), correctly rounded.
    const std::string copy(mantissa, q);
    f = std::strtof(copy.c_str(), nullptr);
  }
  return negative ? -f : f;
}

// Reads `count` numbers of a v, vn or vt line into `out`.
void numbers(const char* p, const char* e, int count, std::vector<float>* out) {
  for (int k = 0; k < count; ++k) {
    p = skip_blanks(p, e);
    const char* w = word_end(p, e);
    out->push_back(number(p, w, 0.0f));
    p = w;
  }
}

constexpr uint8_t FIELD_V = 0, FIELD_VT = 1, FIELD_VN = 2;

// A relative index of a part, resolved against the part's own lines: the merge adds the
// lines of its kind before the part.
struct Relative {
  uint64_t corner;
  int64_t local;
  uint8_t field;
};

// What one thread read of a run of whole lines.
struct Part {
  ObjText text;  // its lines' data, relative indices unresolved
  std::vector<Relative> relative;
};

// The integer at p as atoi reads it (sign, digits; what follows is left), in 64 bits
// clamped far past any index; `digits` false where there are none.
int64_t index_value(const char*& p, const char* e, bool* digits) {
  bool negative = false;
  if (p < e && (*p == '+' || *p == '-')) negative = *p++ == '-';
  int64_t value = 0;
  const char* start = p;
  while (p < e && digit(*p)) {
    if (value < (int64_t{1} << 40)) value = value * 10 + (*p - '0');
    ++p;
  }
  *digits = p > start;
  return negative ? -value : value;
}

// The corner index `value` of a face (THE GRAMMAR), or false for 0. Relative ones are
// recorded for the merge.
bool set_index(int64_t value, uint64_t lines_of_kind, uint64_t corner, uint8_t field, int32_t* out, Part* part) {
  if (value == 0) return false;
  if (value > 0) {
    *out = value - 1 <= INT32_MAX ? static_cast<int32_t>(value - 1) : ObjCorner::OUT_OF_RANGE;
  } else {
    *out = ObjCorner::OUT_OF_RANGE;  // until the merge resolves it
    part->relative.push_back({corner, static_cast<int64_t>(lines_of_kind) + value, field});
  }
  return true;
}

// One corner "v", "v/vt", "v//vn" or "v/vt/vn" at p; false on a missing or zero index,
// *why then saying which field and what it holds.
bool corner(const char*& p, const char* e, Part* part, std::string* why) {
  ObjText& t = part->text;
  const uint64_t at = t.corners.size();
  ObjCorner c;
  const auto field = [&](uint8_t which, int32_t* out) {
    const char* start = p;
    bool digits = false;
    const int64_t value = index_value(p, e, &digits);
    const uint64_t lines = which == FIELD_V ? t.v.size() / 3 : which == FIELD_VT ? t.vt.size() / 2 : t.vn.size() / 3;
    if (!digits || !set_index(value, lines, at, which, out, part)) {
      const char* end = start;
      while (end < e && *end != '/' && !blank(*end) && *end != '\r') ++end;
      const char* name = which == FIELD_V ? "v" : which == FIELD_VT ? "vt" : "vn";
      *why = std::string("its ") + name + " index is " +
             (end == start ? std::string("missing")
              : !digits    ? "not a number: " + quote(std::string(start, end), 24)
                           : std::string("0"));
      return false;
    }
    while (p < e && *p != '/' && !blank(*p) && *p != '\r') ++p;  // the rest of the word
    return true;
  };
  if (!field(FIELD_V, &c.v)) return false;
  if (p < e && *p == '/') {
    ++p;
    if (p < e && *p == '/') {
      ++p;
      if (!field(FIELD_VN, &c.vn)) return false;
    } else {
      if (!field(FIELD_VT, &c.vt)) return false;
      if (p < e && *p == '/') {
        ++p;
        if (!field(FIELD_VN, &c.vn)) return false;
      }
    }
  }
  t.corners.push_back(c);
  return true;
}

bool starts(const char* p, const char* e, const char* word) {
  const size_t n = std::strlen(word);
  return static_cast<size_t>(e - p) >= n && std::memcmp(p, word, n) == 0;
}

// One line's text [p, e) into the part; false (the part's error set) on an error.
bool parse_line(const char* p, const char* e, Part* part) {
  ObjText& t = part->text;
  p = skip_blanks(p, e);
  if (p == e || *p == '#') return true;
  const auto keyword = [&](const char* word) {
    const size_t n = std::strlen(word);
    return starts(p, e, word) && static_cast<size_t>(e - p) > n && blank(p[n]);
  };
  if (keyword("v")) {
    numbers(p + 2, e, 3, &t.v);
  } else if (keyword("vn")) {
    numbers(p + 3, e, 3, &t.vn);
  } else if (keyword("vt")) {
    numbers(p + 3, e, 2, &t.vt);
  } else if (keyword("f")) {
    const size_t first = t.corners.size();
    const size_t first_relative = part->relative.size();
    for (p = skip_blanks(p + 2, e); p < e; p = skip_blanks(p, e)) {
      std::string why;
      if (!corner(p, e, part, &why)) {
        t.error = "f: corner " + std::to_string(t.corners.size() - first + 1) + ": " + why +
                  " (OBJ indices count from 1, or back from -1)";
        return false;
      }
    }
    const size_t n = t.corners.size() - first;
    if (n < 3) {  // skipped, as by other loaders
      t.corners.resize(first);
      part->relative.resize(first_relative);
    } else {
      t.face_sizes.push_back(static_cast<uint32_t>(n));
    }
  } else if (starts(p, e, "usemtl")) {
    const char* name = skip_blanks(p + 6, e);
    t.statements.push_back({ObjStatement::usemtl, t.face_sizes.size(), std::string(name, word_end(name, e))});
  } else if (keyword("mtllib")) {
    t.statements.push_back({ObjStatement::mtllib, t.face_sizes.size(), std::string(p + 7, e)});
  }
  return true;
}

// Parses the lines [p, end) into `part`, counting line ends, until the first error (its
// part-local line kept in error_line), or until `stop_face` faces are stored (the line of
// the last one kept in error_line).
void parse_lines(const char* p, const char* end, Part* part, uint64_t stop_face = UINT64_MAX) {
  ObjText& t = part->text;
  const char* newline = nullptr;  // the next '\n' at or after p (kept: a file of lone '\r's)
  while (p < end) {
    if (newline < p) {
      const void* n = std::memchr(p, '\n', static_cast<size_t>(end - p));
      newline = n ? static_cast<const char*>(n) : end;
    }
    const char* e = newline;
    const char* next = newline < end ? newline + 1 : end;
    if (const void* r = std::memchr(p, '\r', static_cast<size_t>(newline - p))) {
      e = static_cast<const char*>(r);  // "\r\n" or a lone '\r'
      next = e + 1 == newline ? newline + 1 : e + 1;
    }
    const bool ended = e < end;  // a line end was read, not the text's end
    if (const void* nul = std::memchr(p, '\0', static_cast<size_t>(e - p))) e = static_cast<const char*>(nul);
    if (ended) ++t.lines;
    const bool ok = parse_line(p, e, part);
    if (!ok || t.face_sizes.size() >= stop_face) {
      t.error_line = t.lines + (ended ? 0 : 1);
      return;
    }
    p = next;
  }
}

// Appends `part` to `out`, resolving its relative indices with the lines before it; an
// error of the part becomes out's, with its line in the file.
void merge(Part&& part, ObjText* out) {
  ObjText& t = part.text;
  const uint64_t counts[3] = {out->v.size() / 3, out->vt.size() / 2, out->vn.size() / 3};
  const uint64_t first_face = out->face_sizes.size();
  if (!t.error.empty() && out->error.empty()) {
    out->error = std::move(t.error);
    out->error_line = out->lines + t.error_line;
  }
  for (const Relative& r : part.relative) {
    const int64_t index = static_cast<int64_t>(counts[r.field]) + r.local;
    ObjCorner& c = t.corners[r.corner];
    int32_t& field = r.field == FIELD_V ? c.v : r.field == FIELD_VT ? c.vt : c.vn;
    field = index >= 0 && index <= INT32_MAX ? static_cast<int32_t>(index) : ObjCorner::OUT_OF_RANGE;
  }
  const auto append = [](auto& to, auto& from) {
    if (to.empty()) {
      to = std::move(from);
    } else {
      to.insert(to.end(), from.begin(), from.end());
    }
    from = {};
  };
  append(out->v, t.v);
  append(out->vn, t.vn);
  append(out->vt, t.vt);
  append(out->corners, t.corners);
  append(out->face_sizes, t.face_sizes);
  for (ObjStatement& s : t.statements) {
    s.faces_before += first_face;
    out->statements.push_back(std::move(s));
  }
  out->lines += t.lines;
}

// The parts of [p, end) for `threads` threads: split after a '\n' near each share's end.
std::vector<std::pair<const char*, const char*>> split(const char* p, const char* end, int threads) {
  std::vector<std::pair<const char*, const char*>> parts;
  const size_t share = static_cast<size_t>(end - p) / static_cast<size_t>(threads) + 1;
  while (p < end) {
    const char* cut = static_cast<size_t>(end - p) > share ? p + share : end;
    if (cut < end) {
      const void* nl = std::memchr(cut, '\n', static_cast<size_t>(end - cut));
      cut = nl ? static_cast<const char*>(nl) + 1 : end;
    }
    parts.emplace_back(p, cut);
    p = cut;
  }
  return parts;
}

// Calls visit(begin, end) on the file's blocks of whole lines (the last may lack its line
// end), in order, until visit returns false.
template <class Visit>
void for_each_block(const std::string& path, size_t block_bytes, Visit&& visit) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) throw std::runtime_error(std::strerror(errno));
  std::vector<char> buffer(block_bytes);
  size_t held = 0;  // bytes of a line carried over from the last block
  for (;;) {
    if (held == buffer.size()) buffer.resize(2 * buffer.size());  // one line longer than a block
    const size_t got = std::fread(buffer.data() + held, 1, buffer.size() - held, f.get());
    if (got == 0 && std::ferror(f.get())) throw std::runtime_error(std::strerror(errno));
    const size_t size = held + got;
    if (got == 0) {
      if (size > 0) visit(buffer.data(), buffer.data() + size);
      return;
    }
    // Up to the last line end of the buffer ('\n', or a '\r' not just before its end, which
    // may be the first half of "\r\n").
    size_t whole = size;
    while (whole > 0 && buffer[whole - 1] != '\n' && !(buffer[whole - 1] == '\r' && whole < size)) --whole;
    if (whole == 0) {
      held = size;
      continue;
    }
    if (!visit(buffer.data(), buffer.data() + whole)) return;
    std::memmove(buffer.data(), buffer.data() + whole, size - whole);
    held = size - whole;
  }
}

}  // namespace

std::vector<std::string> split_mtllib(const std::string& text) {
  std::vector<std::string> names;
  std::string name;
  bool escaped = false;
  for (const char c : text) {
    if (!escaped && c == '\\') {
      escaped = true;
      continue;
    }
    if (!escaped && c == ' ') {
      if (!name.empty()) names.push_back(name);
      name.clear();
      continue;
    }
    escaped = false;
    name += c;
  }
  if (!name.empty()) names.push_back(name);
  return names;
}

ObjText parse_obj_text(const std::string& text) {
  Part part;
  parse_lines(text.data(), text.data() + text.size(), &part);
  ObjText out;
  merge(std::move(part), &out);
  return out;
}

ObjText read_obj_text(const std::string& path, const ObjReading& reading) {
  ObjText out;
  const size_t most = static_cast<size_t>(thread_count(reading.threads, 64));
  for_each_block(path, std::max<size_t>(reading.block_bytes, 1), [&](const char* p, const char* end) {
    const size_t bytes = static_cast<size_t>(end - p);
    const int n = static_cast<int>(std::clamp<size_t>(bytes / std::max<size_t>(reading.min_part_bytes, 1), 1, most));
    const auto runs = split(p, end, n);
    std::vector<Part> parts(runs.size());
    parallel_for(runs.size(), n, [&](size_t k, int) { parse_lines(runs[k].first, runs[k].second, &parts[k]); });
    for (Part& part : parts) {
      const bool failed = !part.text.error.empty();
      merge(std::move(part), &out);
      if (failed) return false;
    }
    return true;
  });
  return out;
}

uint64_t obj_face_line(const std::string& path, uint64_t face) {
  uint64_t lines = 0, faces = 0, found = 0;
  for_each_block(path, size_t{1} << 20, [&](const char* p, const char* end) {
    Part part;
    parse_lines(p, end, &part, face + 1 - faces);
    if (faces + part.text.face_sizes.size() == face + 1) {
      found = lines + part.text.error_line;
      return false;
    }
    faces += part.text.face_sizes.size();
    lines += part.text.lines;
    return part.text.error.empty();
  });
  return found;
}

}  // namespace abcube
