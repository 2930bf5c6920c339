// The exact camera pass's colour, one shading a pixel and surface (gl_camera_exact.cpp,
// ExactCameraOptions::Shading::pixels). One fragment a pixel of the view's region: its
// 8 x 4 samples (raster/samples.hpp) fall into groups by their key (camera_ids.frag): the
// triangle they show (0: not this view's sample) and the set of volume lights blocked there,
// so that a shadow edge through a pixel stays as sharp as the samples. Each group is shaded
// once (camera_surface.glsl) at its samples' mean position: the ray from the view's eye
// through that point of the sample grid meets the triangle's plane at barycentrics
// (b0, b1, b2), and position, normal and texture coordinates are interpolated with them, as
// the rasteriser interpolates them perspective-correctly at a sample. Each sample of the
// group then gets C = color + weight * C_sample (the per-sample pass's dual-source blend,
// done here on the target's own texel).
// The camera's own view (u_pixels) writes a pixel whose samples all share one key as that
// pixel's (color, weight) instead (u_pixel_color, u_pixel_weight): the box filter of its
// samples is then color + weight * (the mean of what its samples show behind), which
// resolve_samples.frag computes; weight.a = -1 there: the samples hold the pixel.
uniform usampler2D u_keys;
uniform mat4 u_unproject;  // the view's clip coordinates -> position relative to its eye
uniform vec2 u_grid;       // the target's size in samples
uniform dvec3 u_center;    // the view's eye (scene.vert)
uniform bool u_uvs;        // the scene has texture coordinates (Uvs bound)
uniform bool u_portals;    // the scene has planar reflectors (Portals bound)
layout(rgba32f, binding = 0) uniform image2D u_target;
uniform bool u_pixels;  // the camera's own view: uniform pixels go to the two images below
layout(rgba32f, binding = 1) uniform writeonly image2D u_pixel_color;
layout(rgba32f, binding = 2) uniform writeonly image2D u_pixel_weight;
// The scene's arrays (gl_passes.cpp): positions and normals as the soup holds them, 3 floats
// a vertex; each triangle's material.
layout(std430, binding = 3) readonly buffer Positions { float positions[]; };
layout(std430, binding = 4) readonly buffer Uvs { vec2 uvs[]; };
layout(std430, binding = 5) readonly buffer Portals { uint portals[]; };  // per vertex (0: none)
layout(std430, binding = 6) readonly buffer Normals { float normals[]; };
layout(std430, binding = 7) readonly buffer TriangleMaterials { uint material_ids[]; };

vec3 normal_of(uint v) { return vec3(normals[3u * v], normals[3u * v + 1u], normals[3u * v + 2u]); }

vec3 corner(uint v) {
  return vec3(dvec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]) - u_center);
}

// The barycentrics where the ray from the eye (the origin) through the point `grid` of the
// sample grid meets the plane of the triangle r0 r1 r2 (relative to the eye); its centroid
// when the ray runs along the plane.
vec3 barycentrics(vec2 grid, vec3 r0, vec3 r1, vec3 r2) {
  vec4 far = u_unproject * vec4(grid / u_grid * 2.0 - 1.0, 0.5, 1.0);
  vec3 d = far.xyz / far.w;
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

ivec2 base;
ivec2 sample_at(int k) { return base + ivec2(k & 7, k >> 3); }

// Shades the group of samples `members` (bit k: sample k), all showing `key`, and blends
// each of its samples; with `pixel`, writes the pixel's colour and weight instead.
void shade(uvec2 key, uint members, bool pixel) {
  vec2 at = vec2(0.0);
  for (uint m = members; m != 0u; m &= m - 1u) at += vec2(sample_at(findLSB(m))) + 0.5;
  at /= float(bitCount(members));
  uint v0 = 3u * (key.x - 1u);
  vec3 r0 = corner(v0), r1 = corner(v0 + 1u), r2 = corner(v0 + 2u);
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
  volume_from_set = true;
  volume_set = uvec4(key.y, 0u, 0u, 0u);
  vec4 color, weight;
  camera_surface(material, p, normal, od, u_portals ? portals[v0] : 0u, color, weight);
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
  base = ivec2(gl_FragCoord.xy) * ivec2(8, 4);
  // The common case first: one key over the whole pixel.
  uvec2 first = texelFetch(u_keys, base, 0).xy;
  uint same = 1u;
  for (int k = 1; k < 32; ++k) same &= uint(texelFetch(u_keys, sample_at(k), 0).xy == first);
  if (same != 0u && first.x != 0u) {
    shade(first, 0xffffffffu, u_pixels);
    return;
  }
  if (u_pixels) imageStore(u_pixel_weight, ivec2(gl_FragCoord.xy), vec4(-1.0));
  // Else group by group: the first sample left names the next group.
  uint left = 0u;
  for (int k = 0; k < 32; ++k) left |= uint(texelFetch(u_keys, sample_at(k), 0).x != 0u) << uint(k);
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
    left &= ~members;
    shade(key, members, false);
  }
}
