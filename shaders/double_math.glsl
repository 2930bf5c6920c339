// Double-precision helpers that round as the CPU core's glm does: each product and sum in
// glm's order, `precise` so that no multiply and add are fused into one rounding.

double dot3(dvec3 a, dvec3 b) {
  precise double d = a.x * b.x + a.y * b.y + a.z * b.z;
  return d;
}

// glm::length: the square root of the dot product.
double length3(dvec3 a) { return sqrt(dot3(a, a)); }

// glm::cross.
dvec3 cross3(dvec3 a, dvec3 b) {
  precise dvec3 c = dvec3(a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y);
  return c;
}

// +infinity (GLSL has no literal for it).
double inf() { return packDouble2x32(uvec2(0u, 0x7ff00000u)); }

// std::max and std::min exactly (GLSL's leave the sign of a zero and NaN to the GL). The
// comparison is precise: a compiler may otherwise fold the select back into its own max or
// min, which returns either zero of +0 and -0.
double std_max(double a, double b) {
  precise bool less = a < b;
  return less ? b : a;
}
double std_min(double a, double b) {
  precise bool less = b < a;
  return less ? b : a;
}
