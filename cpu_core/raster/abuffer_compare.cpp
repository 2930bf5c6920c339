#include "raster/abuffer_compare.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "base/error.hpp"
#include "raster/cube_map.hpp"

namespace abcube {

namespace {

std::string describe(const Fragment& f) {
  std::ostringstream s;
  s.precision(9);
  s << "z " << f.zmin << ".." << f.zmax << ", mask 0x" << std::hex << f.mask << std::dec << ", triangle "
    << f.triangle() << (f.back_face() ? " (back)" : "") << ", normal 0x" << std::hex << f.normal;
  return s.str();
}

double relative(float x, float y) {
  const double d = std::fabs(double(x) - double(y)), m = std::max(std::fabs(double(x)), std::fabs(double(y)));
  return m > 0.0 ? d / m : 0.0;
}

int code_steps(uint32_t x, uint32_t y) {
  const auto half = [](uint32_t c, int shift) { return static_cast<int>(static_cast<int16_t>(c >> shift)); };
  return std::max(std::abs(half(x, 0) - half(y, 0)), std::abs(half(x, 16) - half(y, 16)));
}

// The class of two fragments at one place of equal-length lists; false when identical.
bool classify(const Fragment& a, const Fragment& b, ListComparison* r, ListDifference* d) {
  if (std::memcmp(&a, &b, sizeof(Fragment)) == 0) return false;
  const double depth = std::max(relative(a.zmin, b.zmin), relative(a.zmax, b.zmax));
  r->depth_max_rel = std::max(r->depth_max_rel, depth);
  if (a.mask != b.mask) {
    *d = ListDifference::mask;
  } else if (a.triangle_and_facing != b.triangle_and_facing) {
    *d = ListDifference::triangle;
  } else if (depth > 0.0) {
    *d = depth > LIST_DEPTH_REL ? ListDifference::depth : ListDifference::depth_close;
  } else {
    *d = code_steps(a.normal, b.normal) > LIST_NORMAL_STEPS ? ListDifference::normal : ListDifference::normal_close;
  }
  return true;
}

}  // namespace

const char* list_difference_name(ListDifference d) {
  switch (d) {
    case ListDifference::length: return "list length";
    case ListDifference::mask: return "coverage mask";
    case ListDifference::triangle: return "triangle or facing";
    case ListDifference::depth: return "depth beyond the bound";
    case ListDifference::depth_close: return "depth within the bound";
    case ListDifference::normal: return "normal beyond one step";
    case ListDifference::normal_close: return "normal within one step";
  }
  return "?";
}

bool ListComparison::within_bounds() const {
  for (ListDifference d : {ListDifference::length, ListDifference::mask, ListDifference::triangle,
                           ListDifference::depth, ListDifference::normal}) {
    if (of(d) > 0) return false;
  }
  return true;
}

namespace {

// One view's lists into `r`; `where` names a pixel of it ("face 2 texel", "pixel").
void compare_view(const ABuffer& a, const ABuffer& b, const std::string& where, const char* a_name, const char* b_name,
                  ListComparison* r) {
  ABCUBE_CHECK(a.view.width == b.view.width && a.view.height == b.view.height,
               "compare_lists: A-buffers of different sizes");
  // The first of each class: where (pixel, fragment index or -1) and what.
  const auto note = [&](ListDifference d, int x, int y, int i, const auto& what) {
    const size_t k = static_cast<size_t>(d);
    if (r->count[k]++ > 0) return;
    r->example[k] = where + " (" + std::to_string(x) + ", " + std::to_string(y) + ")" +
                    (i >= 0 ? " fragment " + std::to_string(i) : std::string()) + ": " + what();
  };
  for (int y = 0; y < a.view.height; ++y) {
    for (int x = 0; x < a.view.width; ++x) {
      const FragmentList la = a.list(x, y), lb = b.list(x, y);
      ++r->lists;
      if (la.size() != lb.size()) {
        note(ListDifference::length, x, y, -1, [&] {
          return std::string(a_name) + " " + std::to_string(la.size()) + " fragments, " + b_name + " " +
                 std::to_string(lb.size());
        });
        continue;
      }
      bool identical = true;
      for (size_t i = 0; i < la.size(); ++i) {
        ++r->fragments;
        ListDifference d;
        if (!classify(la[i], lb[i], r, &d)) {
          ++r->fragments_identical;
          continue;
        }
        identical = false;
        note(d, x, y, static_cast<int>(i), [&] {
          return std::string(a_name) + " {" + describe(la[i]) + "}, " + b_name + " {" + describe(lb[i]) + "}";
        });
      }
      r->lists_identical += identical;
    }
  }
}

}  // namespace

ListComparison compare_lists(const CubeABuffer& a, const CubeABuffer& b, const char* a_name, const char* b_name) {
  ABCUBE_CHECK(a.n == b.n, "compare_lists: cube A-buffers of different resolutions");
  ListComparison r;
  for (int f = 0; f < CUBE_FACES; ++f) {
    compare_view(a.faces[static_cast<size_t>(f)], b.faces[static_cast<size_t>(f)],
                 "face " + std::to_string(f) + " texel", a_name, b_name, &r);
  }
  return r;
}

ListComparison compare_lists(const ABuffer& a, const ABuffer& b, const char* a_name, const char* b_name) {
  ListComparison r;
  compare_view(a, b, "pixel", a_name, b_name, &r);
  return r;
}

}  // namespace abcube
