// The exact camera pass's colour, one shading a pixel and surface (gl_shading_groups.cpp,
// ExactCameraOptions::Shading::pixels). One fragment a pixel of the view's region: its 8 x 4
// samples fall into groups by their key (camera_ids.frag: the triangle they show and the set
// of volume lights blocked there, so a shadow edge stays as sharp as the samples). Each group
// is shaded once (camera_surface.glsl) at its samples' mean position, interpolated as the
// rasteriser would there, and each of its samples gets C = color + weight * C_sample; a
// silhouette of a smooth triangle and a group seen too obliquely (FORESHORTENING) are shaded
// once a sample. docs/design/camera-groups.md has the whole argument.
uniform usampler2D u_keys;
uniform mat4 u_unproject;  // the view's clip coordinates -> position relative to its eye
uniform vec2 u_grid;       // the target's size in samples
uniform dvec3 u_center;    // the view's eye (scene.vert)
uniform bool u_uvs;        // the scene has texture coordinates (Uvs bound)
uniform bool u_portals;    // the scene has planar reflectors (Portals bound)
layout(rgba32f, binding = TARGET_IMAGE) uniform image2D u_target;
uniform bool u_pixels;  // the camera's own view: uniform pixels go to the two images below
layout(rgba32f, binding = PIXEL_COLOR_IMAGE) uniform writeonly image2D u_pixel_color;
layout(rgba32f, binding = PIXEL_WEIGHT_IMAGE) uniform writeonly image2D u_pixel_weight;
// The scene's arrays (gl_scene_buffers.cpp): positions and normals as the soup holds them, 3 floats
// a vertex; each triangle's material.
layout(std430, binding = POSITIONS_BINDING) readonly buffer Positions { float positions[]; };
layout(std430, binding = UVS_BINDING) readonly buffer Uvs { vec2 uvs[]; };
layout(std430, binding = PORTALS_BINDING) readonly buffer Portals { uint portals[]; };  // per vertex (0: none)
layout(std430, binding = NORMALS_BINDING) readonly buffer Normals { float normals[]; };
layout(std430, binding = TRIANGLE_MATERIALS_BINDING) readonly buffer TriangleMaterials { uint material_ids[]; };

vec3 normal_of(uint v) { return vec3(normals[3u * v], normals[3u * v + 1u], normals[3u * v + 2u]); }

vec3 corner(uint v) {
  return vec3(dvec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]) - u_center);
}

// A point on the ray from the view's eye through the point `grid` of the sample grid, in
// homogeneous coordinates (affine in grid), and the ray's direction.
vec4 far_through(vec2 grid) { return u_unproject * vec4(grid / u_grid * 2.0 - 1.0, 0.5, 1.0); }
vec3 ray_through(vec2 grid) {
  vec4 far = far_through(grid);
  return far.xyz / far.w;
}

// The barycentrics where the ray from the eye (the origin) through the point `grid` of the
// sample grid meets the plane of the triangle r0 r1 r2 (relative to the eye); its centroid
// when the ray runs along the plane.
vec3 barycentrics(vec2 grid, vec3 r0, vec3 r1, vec3 r2) {
  vec3 d = ray_through(grid);
  vec3 e1 = r1 - r0, e2 = r2 - r0;
  vec3 p = cross(d, e2);
  float det = dot(e1, p);
  vec3 s = -r0, q = cross(s, e1);
  float u = dot(s, p) / det, v = dot(d, q) / det;
  if (!(abs(u) < 1e30) || !(abs(v) < 1e30)) return vec3(1.0 / 3.0);
  return vec3(1.0 - u - v, u, v);
}

// Whether triangle t's vertex normals differ (a smooth-shaded facet, whose shading turns
// fastest at a silhouette, where a pixel holds more than one key).
bool curved(uint t) {
  vec3 na = normal_of(3u * t);
  return na != normal_of(3u * t + 1u) || na != normal_of(3u * t + 2u);
}

// The portal word camera_surface gets for triangle t.
uint portal_of(uint t) { return u_portals ? portals[3u * t] : 0u; }

ivec2 base;
ivec2 sample_at(int k) { return base + ivec2(k % MASK_COLUMNS, k / MASK_COLUMNS); }

// A triangle's corners relative to the eye (read once a group: storage reads are dear on
// llvmpipe), and its plane: its normal n (not unit) and dot(n, r0).
struct Corners { vec3 r0, r1, r2; };
Corners corners_of(uint t) { return Corners(corner(3u * t), corner(3u * t + 1u), corner(3u * t + 2u)); }
vec4 plane_of(Corners c) {
  vec3 n = cross(c.r1 - c.r0, c.r2 - c.r0);
  return vec4(n, dot(n, c.r0));
}

// The distance from the eye to the plane along the ray through the point `far` of
// far_through, times |n|; not above 0 (or not finite) where the ray runs along the plane or
// meets it behind the eye.
float ray_distance(vec4 plane, vec4 far) {
  vec3 d = far.xyz / far.w;
  return length(d) * (plane.w / dot(plane.xyz, d));
}

// Whether distances in [nearest, farthest] are too far apart (or not all in front).
bool too_oblique(float nearest, float farthest) { return !(nearest > 0.0 && farthest <= nearest * (1.0 + 1.0 / 16.0)); }

// FORESHORTENING. Whether samples of a triangle lie at distances from the eye that differ by
// more than a ratio of 1 + 1/16: a group seen that obliquely (a floor toward its horizon)
// spans a stretch of the surface over which the position is far from linear in the sample
// grid, so the shading at the samples' mean position does not stand for their mean shading
// to second order. Such a group is shaded once a sample. A ray that runs along the plane or
// meets it behind the eye counts as oblique. Over a rectangle of samples (corner samples lo
// and hi) the distance from the eye is convex over its footprint on the plane, so its
// largest is at a corner (and its least too, except where the eye looks at the plane
// head-on, where the ratio is near 1 either way). ray_through is affine before its division,
// so the corners' rays are the centre's plus or minus half the span in each axis.
bool foreshortened(Corners c, ivec2 lo, ivec2 hi) {
  vec4 plane = plane_of(c);
  vec4 mid = far_through(vec2(base) + 0.5 + 0.5 * vec2(lo + hi));
  vec2 half_span = vec2(hi - lo) / u_grid;  // corner - centre, in NDC
  vec4 ex = u_unproject[0] * half_span.x, ey = u_unproject[1] * half_span.y;
  float a0 = ray_distance(plane, mid - ex - ey), a1 = ray_distance(plane, mid + ex - ey);
  float a2 = ray_distance(plane, mid - ex + ey), a3 = ray_distance(plane, mid + ex + ey);
  return too_oblique(min(min(a0, a1), min(a2, a3)), max(max(a0, a1), max(a2, a3)));
}

// The same over the bounding rectangle of the samples `members`.
// (A mask's byte is a row of 8 columns.)
#if MASK_COLUMNS != 8 || MASK_ROWS != 4
#error "group_foreshortened reads a mask as 4 bytes, one a row"
#endif
bool group_foreshortened(Corners c, uint members) {
  uint columns = (members | members >> 8 | members >> 16 | members >> 24) & 0xffu;
  uint rows = uint((members & 0xffu) != 0u) | uint((members & 0xff00u) != 0u) << 1 |
              uint((members & 0xff0000u) != 0u) << 2 | uint((members & 0xff000000u) != 0u) << 3;
  return foreshortened(c, ivec2(findLSB(columns), findLSB(rows)), ivec2(findMSB(columns), findMSB(rows)));
}

// Shades the group of samples `members` (bit k: sample k), all showing `key`, and blends
// each of its samples; with `pixel`, writes the pixel's colour and weight instead. c: the
// corners of key's triangle.
void shade(uvec2 key, uint members, bool pixel, Corners c) {
  vec2 at = vec2(0.0);
  for (uint m = members; m != 0u; m &= m - 1u) at += vec2(sample_at(findLSB(m))) + 0.5;
  at /= float(bitCount(members));
  uint v0 = 3u * (key.x - 1u);
  vec3 r0 = c.r0, r1 = c.r1, r2 = c.r2;
  vec3 b = barycentrics(at, r0, r1, r2);
  vec3 p = b.x * r0 + b.y * r1 + b.z * r2;
  vec3 normal = b.x * normal_of(v0) + b.y * normal_of(v0 + 1u) + b.z * normal_of(v0 + 2u);
  uint material = material_ids[key.x - 1u];
  vec3 od = materials[material].color_ambient.rgb;
  if (u_uvs && materials[material].transmission.w >= 0.0) {
    // The texture at each sample of the group, with the footprint of one sample (as dFdx
    // and dFdy give it in the per-sample pass), averaged: the shading is linear in Od, so
    // the group's colour is the mean of its samples' colours in that term.
    vec3 bx = barycentrics(at + vec2(1.0, 0.0), r0, r1, r2), by = barycentrics(at + vec2(0.0, 1.0), r0, r1, r2);
    mat3x2 uv = mat3x2(uvs[v0], uvs[v0 + 1u], uvs[v0 + 2u]);
    vec2 dx = uv * (bx - b), dy = uv * (by - b);
    od = vec3(0.0);
    for (uint m = members; m != 0u; m &= m - 1u) {
      vec2 s = vec2(sample_at(findLSB(m))) + 0.5;
      od += diffuse_color_footprint(materials[material], uv * barycentrics(s, r0, r1, r2), dx, dy);
    }
    od /= float(bitCount(members));
  }
  // What a curved mirror or a refraction shows of the environment map can change within a
  // pixel by a whole edge of the map's content: one lookup at the samples' mean is no
  // second-order stand-in for the mean of theirs (a pixel of a mirror sphere across such an
  // edge would take one side's colour). So that term is the mean of the lookups at the
  // group's samples, each at its own point and normal.
  uint portal = portal_of(key.x - 1u);
  vec3 environment = vec3(0.0);
  if (camera_looks_up(material, portal)) {
    vec3 n0 = normal_of(v0), n1 = normal_of(v0 + 1u), n2 = normal_of(v0 + 2u);
    for (uint m = members; m != 0u; m &= m - 1u) {
      vec3 bs = barycentrics(vec2(sample_at(findLSB(m))) + 0.5, r0, r1, r2);
      environment += camera_environment(material, bs.x * r0 + bs.y * r1 + bs.z * r2, bs.x * n0 + bs.y * n1 + bs.z * n2,
                                        portal);
    }
    environment /= float(bitCount(members));
  }
  volume_from_set = true;
  volume_set = uvec4(key.y, 0u, 0u, 0u);
  vec4 color, weight;
  camera_surface(material, p, normal, od, portal, environment, color, weight);
  if (pixel) {
    imageStore(u_pixel_color, ivec2(gl_FragCoord.xy), color);
    imageStore(u_pixel_weight, ivec2(gl_FragCoord.xy), weight);
  } else if (weight == vec4(0.0)) {
    for (uint m = members; m != 0u; m &= m - 1u) imageStore(u_target, sample_at(findLSB(m)), color);
  } else {
    for (uint m = members; m != 0u; m &= m - 1u) {
      ivec2 s = sample_at(findLSB(m));
      imageStore(u_target, s, color + weight * imageLoad(u_target, s));
    }
  }
}

void main() {
  base = ivec2(gl_FragCoord.xy) * ivec2(MASK_COLUMNS, MASK_ROWS);
  // The common case first: one key over the whole pixel.
  uvec2 first = texelFetch(u_keys, base, 0).xy;
  uint same = 1u;
  for (int k = 1; k < MASK_SAMPLES; ++k) same &= uint(texelFetch(u_keys, sample_at(k), 0).xy == first);
  if (same != 0u && first.x != 0u) {
    Corners c = corners_of(first.x - 1u);
    if (!foreshortened(c, ivec2(0), ivec2(MASK_COLUMNS - 1, MASK_ROWS - 1))) {
      shade(first, 0xffffffffu, u_pixels, c);
      return;
    }
  }
  if (u_pixels) imageStore(u_pixel_weight, ivec2(gl_FragCoord.xy), vec4(-1.0));
  // Else group by group: the first sample left names the next group.
  uint left = 0u;
  for (int k = 0; k < MASK_SAMPLES; ++k) left |= uint(texelFetch(u_keys, sample_at(k), 0).x != 0u) << uint(k);
  while (left != 0u) {
    uvec2 key = texelFetch(u_keys, sample_at(findLSB(left)), 0).xy;
    uint members = 0u;
    if (curved(key.x - 1u)) {
      members = 1u << uint(findLSB(left));
    } else {
      for (uint m = left; m != 0u; m &= m - 1u) {
        int k = findLSB(m);
        members |= uint(texelFetch(u_keys, sample_at(k), 0).xy == key) << uint(k);
      }
    }
    Corners c = corners_of(key.x - 1u);
    // FORESHORTENING: its first sample alone; the rest are grouped again.
    if (bitCount(members) > 1 && group_foreshortened(c, members)) members &= -members;
    left &= ~members;
    shade(key, members, false, c);
  }
}
