// The OBJ reader (cpu_core/scene/obj_text.hpp): THE GRAMMAR line by line, the same result
// on any number of threads and blocks, and the same geometry as tinyobjloader (which read
// OBJ files before) on every OBJ file of the repository and of assimp's test models.
#include <tiny_obj_loader.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "scene/obj_text.hpp"
#include "scene_load_fixtures.hpp"

namespace abcube {
namespace {

using scene_test::TempDir;

std::vector<float> floats(std::initializer_list<float> f) { return f; }

TEST(ObjText, ReadsTheStatementsARenderUses) {
  const ObjText t = parse_obj_text(
      "# a comment\n"
      "mtllib a.mtl\n"
      "  v 1 2 3\n"
      "v\t4 5 6 1.0 0.5 0.5 0.5\n"  // w and colours ignored
      "v 7 8 9\n"
      "vn 0 1 0\n"
      "vt 0.25 0.75 0\n"
      "vp 1 2 3\n"  // ignored, as are g, o, s, l and p
      "g group\no object\ns 1\nl 1 2\np 1\n"
      "usemtl red\n"
      "f 1 2 3\n"
      "f 1/1 2/1 3/1\n"
      "usemtl  blue  extra\n"
      "f 1//1 2//1 3//1 1/1/1\n"
      "fo 1 2 3\n");  // not a face
  EXPECT_EQ(t.v, floats({1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(t.vn, floats({0, 1, 0}));
  EXPECT_EQ(t.vt, floats({0.25f, 0.75f}));
  ASSERT_EQ(t.face_sizes, std::vector<uint32_t>({3, 3, 4}));
  ASSERT_EQ(t.corners.size(), 10u);
  const int32_t A = ObjCorner::ABSENT;
  const int32_t expect[10][3] = {{0, A, A}, {1, A, A}, {2, A, A}, {0, 0, A}, {1, 0, A},
                                 {2, 0, A}, {0, A, 0}, {1, A, 0}, {2, A, 0}, {0, 0, 0}};
  for (size_t k = 0; k < 10; ++k) {
    EXPECT_EQ(t.corners[k].v, expect[k][0]) << k;
    EXPECT_EQ(t.corners[k].vt, expect[k][1]) << k;
    EXPECT_EQ(t.corners[k].vn, expect[k][2]) << k;
  }
  ASSERT_EQ(t.statements.size(), 3u);
  EXPECT_EQ(t.statements[0].kind, ObjStatement::mtllib);
  EXPECT_EQ(t.statements[0].text, "a.mtl");
  EXPECT_EQ(t.statements[0].faces_before, 0u);
  EXPECT_EQ(t.statements[1].kind, ObjStatement::usemtl);
  EXPECT_EQ(t.statements[1].text, "red");
  EXPECT_EQ(t.statements[2].text, "blue");  // the first word
  EXPECT_EQ(t.statements[2].faces_before, 2u);
  EXPECT_EQ(t.lines, 19u);
  EXPECT_TRUE(t.error.empty());
}

TEST(ObjText, NumbersAreTheLongestPrefixOfTheirWord) {
  const float inf = std::numeric_limits<float>::infinity();
  const ObjText t = parse_obj_text(
      "v 1 2. 3.0\n"
      "v +1 -.5 .25\n"
      "v 1e2 2.E+1 3.1+e2\n"  // "3.1+e2" is 3.1
      "v 1e 1e+ x\n"          // no number: 0
      "v 1,5 7abc -\n"
      "v 1e999 -1e999 1e-999\n"
      "v 0.1 16777217 3.4028235e38\n"
      "v 5\n");  // missing: 0
  const std::vector<float> expect = {1, 2, 3, 1,   -0.5f, 0.25f, 100,  20,          3.1f,          0, 0, 0,
                                     1, 7, 0, inf, -inf,  0,     0.1f, 16777216.0f, 3.4028235e38f, 5, 0, 0};
  ASSERT_EQ(t.v.size(), expect.size());
  for (size_t k = 0; k < expect.size(); ++k) EXPECT_EQ(t.v[k], expect[k]) << "value " << k;
  EXPECT_FALSE(std::signbit(t.v[17]));  // 1e-999 underflows to +0
}

TEST(ObjText, RelativeIndicesCountBackFromTheLastLineBefore) {
  const ObjText t = parse_obj_text(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\n"
      "f -3/-1 -2/-1 -1/-1\n"
      "v 0 0 1\n"
      "f -1 -2 -3\n"
      "f -5 1 2\n");  // before the first v
  ASSERT_EQ(t.corners.size(), 9u);
  EXPECT_EQ(t.corners[0].v, 0);
  EXPECT_EQ(t.corners[2].v, 2);
  EXPECT_EQ(t.corners[0].vt, 0);
  EXPECT_EQ(t.corners[3].v, 3);
  EXPECT_EQ(t.corners[5].v, 1);
  EXPECT_EQ(t.corners[6].v, ObjCorner::OUT_OF_RANGE);
  EXPECT_EQ(t.corners[7].v, 0);
}

TEST(ObjText, FacesOfFewerThanThreeCornersAreSkipped) {
  const ObjText t = parse_obj_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf\nf 1 -1\nf 1 2 3\nusemtl m\n");
  EXPECT_EQ(t.face_sizes, std::vector<uint32_t>({3}));
  EXPECT_EQ(t.corners.size(), 3u);
  ASSERT_EQ(t.statements.size(), 1u);
  EXPECT_EQ(t.statements[0].faces_before, 1u);
}

TEST(ObjText, AZeroOrMissingIndexIsAnErrorOfItsLine) {
  for (const char* bad : {"f 1 0 2", "f 1 2 x", "f 1/ 2 3", "f 1// 2 3", "f 1/2/ 2 3", "f 1 +0 2"}) {
    // Line ends of every kind before it: "\n", "\r\n" and a lone "\r".
    const ObjText t = parse_obj_text(std::string("v 0 0 0\r\nv 1 0 0\rv 0 1 0\n\n") + bad + "\nf 1 2 3\n");
    EXPECT_EQ(t.error_line, 5u) << bad;
    EXPECT_NE(t.error.find("f: corner "), std::string::npos) << t.error;
  }
  const ObjText last = parse_obj_text("v 0 0 0\nf 0 1 1");  // no line end at the end
  EXPECT_EQ(last.error_line, 2u);
  EXPECT_EQ(last.error, "f: corner 1: its v index is 0 (OBJ indices count from 1, or back from -1)");
  // What the index holds is named: a word that is no number, a missing one.
  EXPECT_EQ(parse_obj_text("v 0 0 0\nf 1 1 x").error,
            "f: corner 3: its v index is not a number: \"x\" (OBJ indices count from 1, or back from -1)");
  EXPECT_EQ(parse_obj_text("v 0 0 0\nf 1/ 1 1").error,
            "f: corner 1: its vt index is missing (OBJ indices count from 1, or back from -1)");
}

TEST(ObjText, ALineEndsAtItsEndAndItsTextAtANul) {
  const std::string text = std::string("v 1 2 3\rv 4 5 6\r\nv 7 8 9") + '\0' + " 10\nv 10 11 12";
  const ObjText t = parse_obj_text(text);
  EXPECT_EQ(t.v, floats({1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}));
  EXPECT_EQ(t.lines, 3u);
}

TEST(ObjText, MtllibSplitsAtSpacesABackslashKeepingTheNext) {
  EXPECT_EQ(split_mtllib("a.mtl b\\ c.mtl  d\\\\e.mtl "), std::vector<std::string>({"a.mtl", "b c.mtl", "d\\e.mtl"}));
  EXPECT_TRUE(split_mtllib("  ").empty());
}

void expect_same(const ObjText& a, const ObjText& b, const std::string& what) {
  EXPECT_EQ(a.v, b.v) << what;
  EXPECT_EQ(a.vn, b.vn) << what;
  EXPECT_EQ(a.vt, b.vt) << what;
  EXPECT_EQ(a.face_sizes, b.face_sizes) << what;
  ASSERT_EQ(a.corners.size(), b.corners.size()) << what;
  for (size_t k = 0; k < a.corners.size(); ++k) {
    ASSERT_TRUE(a.corners[k].v == b.corners[k].v && a.corners[k].vt == b.corners[k].vt &&
                a.corners[k].vn == b.corners[k].vn)
        << what << ": corner " << k;
  }
  ASSERT_EQ(a.statements.size(), b.statements.size()) << what;
  for (size_t k = 0; k < a.statements.size(); ++k) {
    EXPECT_EQ(a.statements[k].kind, b.statements[k].kind) << what;
    EXPECT_EQ(a.statements[k].text, b.statements[k].text) << what;
    EXPECT_EQ(a.statements[k].faces_before, b.statements[k].faces_before) << what;
  }
  EXPECT_EQ(a.lines, b.lines) << what;
  EXPECT_EQ(a.error_line, b.error_line) << what;
  EXPECT_EQ(a.error, b.error) << what;
}

// A seeded OBJ text of what exporters write, and what they get wrong: absolute and
// relative indices, every corner form, polygons, materials, comments, blank lines, every
// line end, and (with `error_at` > 0) a zero index on that face line. line_of_face: the
// 1-based line of each stored face.
std::string random_obj(uint32_t seed, int statements, int error_at, std::vector<uint64_t>* line_of_face) {
  std::mt19937 rng(seed);
  const auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<uint32_t>(n)); };
  std::ostringstream out;
  int v = 0, vt = 0, vn = 0, faces = 0;
  uint64_t line = 0;
  const char* ends[] = {"\n", "\r\n", "\r"};
  for (int s = 0; s < statements; ++s) {
    const int kind = pick(20);
    ++line;
    if (kind < 6 || v < 3) {
      out << (pick(4) == 0 ? "  v " : "v ") << pick(2000) - 1000 << "." << pick(1000) << " " << pick(100) * 0.37 << " -"
          << pick(50) << "e-" << pick(3);
      ++v;
    } else if (kind < 8) {
      out << "vn 0 " << pick(3) << " 1";
      ++vn;
    } else if (kind < 10) {
      out << "vt " << pick(100) / 100.0 << " " << pick(100) / 100.0;
      ++vt;
    } else if (kind < 17) {
      const int n = 3 + (pick(3) == 0 ? pick(5) : 0);
      const int form = pick(4);  // v, v/vt, v//vn, v/vt/vn
      out << "f";
      const bool bad = error_at > 0 && faces + 1 == error_at;
      for (int k = 0; k < n; ++k) {
        const auto index = [&](int count) {
          const int i = pick(count);
          return pick(3) == 0 ? std::to_string(i - count) : std::to_string(i + 1);
        };
        out << (pick(5) == 0 ? "\t" : " ") << (bad && k == 1 ? "0" : index(v));
        if ((form == 1 || form == 3) && vt > 0) out << "/" << index(vt);
        if ((form == 2 || form == 3) && vn > 0) out << ((form == 2 || vt == 0) ? "//" : "/") << index(vn);
      }
      ++faces;
      if (line_of_face) line_of_face->push_back(line);
    } else if (kind == 17) {
      out << (pick(2) ? "usemtl m" : "mtllib lib") << pick(4) << (pick(2) ? ".mtl" : "");
    } else if (kind == 18) {
      out << (pick(2) ? "# comment f 0 0 0" : "g part");
    } else {
      out << (pick(2) ? " " : "s off");  // not empty: "\r" then "\n" would be one line end
    }
    out << ends[pick(8) == 0 ? 1 + pick(2) : 0];
  }
  return out.str();
}

TEST(ObjText, TheSameOnAnyNumberOfThreadsAndBlocks) {
  TempDir dir;
  for (uint32_t seed = 1; seed <= 12; ++seed) {
    const int error_at = seed % 3 == 0 ? static_cast<int>(seed * 37 % 400) + 1 : 0;
    const std::string text = random_obj(seed, 2000, error_at, nullptr);
    const std::string file = dir.write("m" + std::to_string(seed) + ".obj", text);
    const ObjText one = parse_obj_text(text);
    EXPECT_EQ(one.error.empty(), error_at == 0) << "seed " << seed;
    if (error_at == 0) EXPECT_GT(one.face_count(), 100u);
    for (const ObjReading r : {ObjReading{1, 64, 16}, ObjReading{3, 4096, 16}, ObjReading{2, 977, 100},
                               ObjReading{4, size_t{1} << 20, 512}, ObjReading{}}) {
      expect_same(read_obj_text(file, r), one,
                  "seed " + std::to_string(seed) + ", " + std::to_string(r.threads) + " threads, blocks of " +
                      std::to_string(r.block_bytes));
    }
  }
}

TEST(ObjText, FaceLineFindsEachFaceAgain) {
  TempDir dir;
  std::vector<uint64_t> lines;
  const std::string text = random_obj(99, 3000, 0, &lines);
  const std::string file = dir.write("m.obj", text);
  ASSERT_EQ(parse_obj_text(text).face_count(), lines.size());
  for (size_t f = 0; f < lines.size(); f += 7) EXPECT_EQ(obj_face_line(file, f), lines[f]) << "face " << f;
  EXPECT_EQ(obj_face_line(file, lines.size() - 1), lines.back());
  EXPECT_EQ(obj_face_line(file, lines.size()), 0u);
}

// Every OBJ file of the repository and of assimp's test models, read by tinyobjloader:
// the same values (to float rounding: tinyobjloader's decimal conversion is not always
// correctly rounded), the same faces and corners.
TEST(ObjText, TheSameGeometryAsTinyobjloader) {
  namespace fs = std::filesystem;
  std::vector<std::string> files;
  for (const std::string root : {std::string(ABCUBE_SOURCE_DIR), std::string("/usr/share/assimp/models")}) {
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(root, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
      const std::string p = it->path().string();
      const std::string inside = p.substr(root.size());
      if (inside.rfind("/build", 0) == 0 || inside.rfind("/.git", 0) == 0) continue;
      if (it->is_regular_file() && it->path().extension() == ".obj" && it->file_size() < (size_t{64} << 20))
        files.push_back(p);
    }
  }
  ASSERT_GT(files.size(), 5u);
  size_t compared = 0;
  for (const std::string& file : files) {
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warning, error;
    std::ifstream in(file);
    tinyobj::MaterialFileReader none("/nonexistent/");
    const bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warning, &error, &in, &none, false, false);
    const ObjText t = read_obj_text(file);
    EXPECT_EQ(ok, t.error.empty()) << file << ": " << error << " / " << t.error;
    if (!ok) continue;
    ++compared;
    const auto near = [](const std::vector<float>& a, const std::vector<float>& b) {
      if (a.size() != b.size()) return false;
      for (size_t k = 0; k < a.size(); ++k) {
        if (a[k] != b[k] && std::fabs(a[k] - b[k]) > 2 * std::numeric_limits<float>::epsilon() * std::fabs(a[k]))
          return false;
      }
      return true;
    };
    EXPECT_TRUE(near(t.v, attrib.vertices)) << file;
    EXPECT_TRUE(near(t.vn, attrib.normals)) << file;
    EXPECT_TRUE(near(t.vt, attrib.texcoords)) << file;
    std::vector<uint32_t> sizes;
    std::vector<ObjCorner> corners;
    for (const tinyobj::shape_t& s : shapes) {
      for (const auto n : s.mesh.num_face_vertices) sizes.push_back(n);
      for (const tinyobj::index_t& i : s.mesh.indices)
        corners.push_back({i.vertex_index, i.texcoord_index, i.normal_index});
    }
    // tinyobjloader keeps a face's corner count in 8 bits (box_longline.obj's face of 936
    // corners counts 168 there, and the faces after it start at the wrong corners).
    std::vector<uint32_t> wrapped;
    for (const uint32_t n : t.face_sizes) wrapped.push_back(n % 256);
    EXPECT_EQ(wrapped, sizes) << file;
    ASSERT_EQ(t.corners.size(), corners.size()) << file;
    for (size_t k = 0; k < corners.size(); ++k) {
      ASSERT_TRUE(t.corners[k].v == corners[k].v && t.corners[k].vt == corners[k].vt &&
                  t.corners[k].vn == corners[k].vn)
          << file << ": corner " << k;
    }
  }
  EXPECT_GT(compared, 5u);
}

}  // namespace
}  // namespace abcube
