// What the candidate scan (cube_scan.comp) and the crossing test (cube_refine.comp) share
// (host/gl/gl_cube_scan.cpp has the same layouts): the searches' rays and the candidates.

// A search's ray (SearchRay): origin relative to the centre (xyz) and l_max (w); unit
// direction (xyz) and self offset (w); the object a refraction exit is restricted to and its
// row of objects allowed (NO_ROW: not restricted); the self tolerance (x).
struct ScanRay {
  dvec4 w_lmax;
  dvec4 d_self;
  uvec4 object_row;
  dvec2 self_tolerance;
};
// A candidate. The scan writes the batch's texel, the fragment, the ray (in the batch), the
// fragment's triangle and facing (id), the texel's interval, its place on its face (i | j <<
// 16) and the end of the texel the walk crossed before (-inf for the first); the crossing
// test adds its answer: flags (1 tested, 2 exact, 4 valid, 8 the surface found is a back
// face), l, the distance from the triangle in texels, the triangle found and the triangles
// the mesh refinement tested.
struct CandidateOut {
  uint texel, fragment, ray, id;
  double l, outside;
  dvec2 interval;
  uint flags, triangle, mesh_tested, ij;
  double before_l1, pad;
};

layout(std430, binding = CUBE_SCAN_RAYS_BINDING) readonly buffer Rays { ScanRay rays[]; };
// The count of candidates found, then up to candidate_room of them.
layout(std430, binding = CUBE_SCAN_CANDIDATES_BINDING) buffer Candidates {
  uint candidate_count;
  uint candidate_pad[3];
  CandidateOut candidates[];
};

const uint BACK_FACE_BIT = 0x80000000u;
