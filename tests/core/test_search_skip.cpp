// The searches' skip of empty faces (search.cpp, scan "EMPTY FACES"): SearchContext::
// empty_ahead against a brute-force look at every texel a walk could still visit, and the
// walk's leave_face against the full walk.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "raster/abuffer.hpp"
#include "search/cube_walk.hpp"
#include "scene/scene_load.hpp"
#include "search/search.hpp"

namespace abcube {
namespace {

// Does any texel (i', j') with i' - i of the sign of si (or 0) and j' - j of the sign of sj
// (or 0) hold a fragment? si == 0 means column i only, sj == 0 row j only.
bool occupied_ahead(const ABuffer& b, int n, int i, int j, int si, int sj) {
  for (int y = 0; y < n; ++y) {
    if ((sj > 0 && y < j) || (sj < 0 && y > j) || (sj == 0 && y != j)) continue;
    for (int x = 0; x < n; ++x) {
      if ((si > 0 && x < i) || (si < 0 && x > i) || (si == 0 && x != i)) continue;
      if (!b.list(x, y).empty()) return true;
    }
  }
  return false;
}

TEST(SearchSkip, EmptyAheadNeverHidesAFragment) {
  const SceneData scene = load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/default.json");
  const int n = 24;
  ABufferOptions options;
  options.threads = 2;
  const CubeABuffer cube = build_cube_abuffer(scene, scene.camera.position, n, options);
  const SearchContext ctx(scene, cube);
  int empty = 0, occupied = 0;
  for (int face = 0; face < CUBE_FACES; ++face) {
    const ABuffer& b = cube.faces[static_cast<size_t>(face)];
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        for (int si = -1; si <= 1; ++si) {
          for (int sj = -1; sj <= 1; ++sj) {
            const bool truth = occupied_ahead(b, n, i, j, si, sj);
            const bool claim = ctx.empty_ahead(face, i, j, si, sj);
            // Never "empty" where a fragment lies ahead; exact for the quadrants (si != 0).
            if (truth) EXPECT_FALSE(claim) << "face " << face << " (" << i << ", " << j << ") " << si << sj;
            if (si != 0) EXPECT_EQ(claim, !truth) << "face " << face << " (" << i << ", " << j << ") " << si << sj;
            (claim ? empty : occupied) += 1;
          }
        }
      }
    }
  }
  // The scene has both: a floor and objects below the camera, open sky above.
  EXPECT_GT(empty, 0);
  EXPECT_GT(occupied, 0);
}

// leave_face: the walk resumes on the next face where the full walk enters it.
TEST(SearchSkip, LeaveFaceResumesOnTheNextFace) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 16;
  int checked = 0;
  for (int k = 0; k < 200; ++k) {
    const glm::dvec3 w(u(rng) * 3, u(rng) * 3, u(rng) * 3);
    const glm::dvec3 d = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
    std::vector<WalkTexel> full;
    CubeWalk all(w, d, n);
    for (WalkTexel t; all.next(&t);) full.push_back(t);
    // Leave the first face after its first texel: the rest must be the full walk's texels
    // from the first texel on another face.
    CubeWalk skipping(w, d, n);
    WalkTexel t;
    ASSERT_TRUE(skipping.next(&t));
    skipping.leave_face();
    size_t at = 0;
    while (at < full.size() && full[at].face == full.front().face) ++at;
    for (; skipping.next(&t); ++at) {
      ASSERT_LT(at, full.size());
      EXPECT_EQ(t.face, full[at].face);
      EXPECT_EQ(t.i, full[at].i);
      EXPECT_EQ(t.j, full[at].j);
      EXPECT_EQ(t.l0, full[at].l0);
      EXPECT_EQ(t.l1, full[at].l1);
      ++checked;
    }
    EXPECT_EQ(at, full.size());
  }
  EXPECT_GT(checked, 100);
}

}  // namespace
}  // namespace abcube
