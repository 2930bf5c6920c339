// The statements of a Wavefront OBJ file that a render uses, read on several threads.
//
// THE GRAMMAR (docs/models-and-textures.md "OBJ and MTL"; tinyobjloader's, which read these
// files before, so that every file it read reads the same):
// - A line ends at "\n", "\r\n" or a lone "\r"; its text ends there or at a NUL byte.
//   Blanks (space, tab) before a statement are skipped; "#" starts a comment line.
// - `v x y z`, `vn x y z`, `vt u v`: the first 3, 3 and 2 numbers (more are ignored: w,
//   vertex colours). A number is the longest prefix of its word of the form
//   [+-] (digits [. digits] | . digits) [(e|E) [+-] digits]; a word with no such prefix, or
//   one missing, is 0.
// - `f c1 c2 c3 ...`: corners `v`, `v/vt`, `v//vn` or `v/vt/vn`, each index an integer
//   (what follows its digits up to the next '/' or blank is skipped): k > 0 is the k-th
//   line of its kind, k < 0 counts back from the last one before the face, 0 or no digits
//   is an error of the line. A face of fewer than 3 corners is skipped.
// - `usemtl NAME` (its first word) and `mtllib FILES` (the rest of the line) are kept in
//   file order with the number of faces before them, for the caller to resolve.
// - Every other statement (`g`, `o`, `s`, `l`, `p`, ...) is ignored.
//
// PARALLEL READING: the file is read in blocks of whole lines, each block split at line
// ends into one part a thread. A part's data depends only on its own lines, except a
// relative index, which its part records and the merge resolves with the counts of the
// parts before it: the result is the same for any number of threads and any block size.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace abcube {

// One corner of a face: 0-based indices of the file's v, vt and vn lines. vt and vn are
// ABSENT where the corner names none; an index that names no line of the file that could
// be (a relative one before the first, one past 2^31) is OUT_OF_RANGE.
struct ObjCorner {
  static constexpr int32_t ABSENT = -1;
  static constexpr int32_t OUT_OF_RANGE = INT32_MIN;
  int32_t v = 0, vt = ABSENT, vn = ABSENT;
};

struct ObjStatement {
  enum Kind : uint8_t { usemtl, mtllib };
  Kind kind = usemtl;
  uint64_t faces_before = 0;  // faces stored before it
  std::string text;           // usemtl: the name; mtllib: the rest of the line
};

struct ObjText {
  std::vector<float> v, vn, vt;          // 3, 3 and 2 per line
  std::vector<ObjCorner> corners;        // the faces' corners, face after face
  std::vector<uint32_t> face_sizes;      // corners of each stored face (3 or more)
  std::vector<ObjStatement> statements;  // usemtl and mtllib, in file order
  uint64_t lines = 0;                    // line ends read
  uint64_t error_line = 0;               // 1-based line of the first error, 0 for none
  std::string error;                     // what is wrong there
  size_t face_count() const { return face_sizes.size(); }
};

// How read_obj_text divides the work (tests set these small).
struct ObjReading {
  int threads = 0;                           // at most; 0: the hardware's
  size_t block_bytes = size_t{16} << 20;     // read at once
  size_t min_part_bytes = size_t{64} << 10;  // a thread's least share of a block
};

// Reads the OBJ file `path` (its size already checked), stopping at the first error of a
// line (ObjText::error). Throws std::runtime_error when the file cannot be read.
ObjText read_obj_text(const std::string& path, const ObjReading& reading = {});

// The same from text in memory, on one thread.
ObjText parse_obj_text(const std::string& text);

// The 1-based line of stored face `face` (ObjText::face_sizes' index) of the file `path`,
// 0 when it has fewer faces (for messages: it reads the file again).
uint64_t obj_face_line(const std::string& path, uint64_t face);

// mtllib's list of files: split at spaces, a backslash keeping the character after it.
std::vector<std::string> split_mtllib(const std::string& text);

}  // namespace abcube
