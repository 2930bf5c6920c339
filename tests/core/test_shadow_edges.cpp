// The second pass of SHADOW EDGES (shadow_edges.hpp): which pixels' lights are searched
// again from every sample, from what each pixel's shading points saw.
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "shading/shadow_edges.hpp"

namespace abcube {
namespace {

constexpr int W = 3, H = 1;
constexpr uint64_t L0 = 1, L1 = 2;

// Three pixels in a row; `lit` and `dark`: what each one's points saw, light by light;
// `sides`: where each one's samples found shadowed or lit ones (PixelShadows::sides).
std::vector<uint64_t> across(std::vector<uint64_t> lit, std::vector<uint64_t> dark, std::vector<uint8_t> sides = {},
                             const std::vector<uint8_t>* only = nullptr) {
  PixelShadows seen;
  seen.lit = std::move(lit);
  seen.dark = std::move(dark);
  seen.sides = std::move(sides);
  return seen.across(W, H, only);
}

constexpr uint8_t DARK_LEFT = SIDE_LEFT, DARK_RIGHT = SIDE_RIGHT;
constexpr uint8_t LIT_LEFT = SIDE_LEFT << PixelShadows::LIT_SIDES;
constexpr uint8_t LIT_RIGHT = SIDE_RIGHT << PixelShadows::LIT_SIDES;

TEST(ShadowEdgesAcross, PixelsThatAllAgreeAreNotSearchedAgain) {
  EXPECT_EQ(across({L0 | L1, L0 | L1, L0 | L1}, {0, 0, 0}), (std::vector<uint64_t>{0, 0, 0}));
  EXPECT_EQ(across({0, 0, 0}, {L0, L0, L0}), (std::vector<uint64_t>{0, 0, 0}));
}

// An edge between two pixels' points: both sides, that light only.
TEST(ShadowEdgesAcross, AnEdgeBetweenTwoPixelsFlagsBothForItsLight) {
  EXPECT_EQ(across({L0 | L1, L1, L1}, {0, L0, L0}), (std::vector<uint64_t>{L0, L0, 0}));
}

// A straight edge through the middle pixel, its shadowed samples on its right: the pixel on
// the right already saw the shadow; the one on the left, whose side of the middle pixel is
// lit, is not searched again.
TEST(ShadowEdgesAcross, AnEdgeInsideAPixelLeavesTheNeighbourOnItsLitSideAlone) {
  EXPECT_EQ(across({L0, L0, 0}, {0, L0, L0}, {0, LIT_LEFT | DARK_RIGHT, 0}), (std::vector<uint64_t>{0, 0, 0}));
}

// A shadow thinner than the points' spacing, met by one point of the middle pixel, whose
// samples found it on both sides: it goes on into both neighbours between their points, and
// they are searched again. The middle pixel refines that light already, its points
// disagreeing.
TEST(ShadowEdgesAcross, AThinShadowOnePointMetFlagsTheNeighboursItRunsInto) {
  const uint8_t both = DARK_LEFT | DARK_RIGHT | LIT_LEFT | LIT_RIGHT;
  EXPECT_EQ(across({L0, L0 | L1, L0}, {0, L0, 0}, {0, both, 0}), (std::vector<uint64_t>{L0, 0, L0}));
  // The same pixels with no samples searched (the points' answers only): nothing is known
  // of where the shadow goes.
  EXPECT_EQ(across({L0, L0, L0}, {0, L0, 0}), (std::vector<uint64_t>{0, 0, 0}));
  // The reverse: a thin gap of light in a shadow.
  EXPECT_EQ(across({0, L0, 0}, {L0, L0, L0}, {0, both, 0}), (std::vector<uint64_t>{L0, 0, L0}));
}

TEST(ShadowEdgesAcross, PixelsOutsideOnlyAreLeftAlone) {
  const std::vector<uint8_t> only = {0, 1, 1};
  const uint8_t both = DARK_LEFT | DARK_RIGHT | LIT_LEFT | LIT_RIGHT;
  EXPECT_EQ(across({L0, L0, L0}, {0, L0, 0}, {0, both, 0}, &only), (std::vector<uint64_t>{0, 0, L0}));
}

}  // namespace
}  // namespace abcube
