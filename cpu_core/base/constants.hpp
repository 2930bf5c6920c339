// Mathematical constants, defined once: every file that needs one includes this (a second
// definition in another file would collide when a unity build compiles them together).
#pragma once

namespace abcube {

inline constexpr double PI = 3.14159265358979323846;

}  // namespace abcube
