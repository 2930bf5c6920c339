// The constants the C++ side of the GL passes and their shaders share: storage-buffer and
// image bindings, the array bounds, the 4x8 sample grid. Defined here once; every shader
// is compiled with glsl_prelude() after its #version line, which #defines each of them by
// the same name with the value given here, so that no shader states a binding or a bound of
// its own (tests/docs/test_docs.py test_shaders_take_shared_constants_from_the_prelude).
#pragma once
#include <string>

#include "base/samples.hpp"
#include "search/search.hpp"

namespace abcube {

// Translucent shadow casters peeled per light, at most (gl_shadow_maps.cpp; common_scene.glsl
// samples them). Crossings beyond the last layer let the light through.
constexpr int MAX_SHADOW_PEELS = 8;
// Base-colour textures on the GPU: the scene's images (scene/texture.hpp, linear RGB) are
// uploaded once per GlScene as RGB32F 2D arrays with GL's mipmaps, one array per distinct
// image size, at most this many (common_scene.glsl; more is a RuntimeFailure naming the
// limit). The uvs go in a vertex buffer of their own, made only when the scene has them.
constexpr int MAX_TEXTURE_ARRAYS = 4;

// Storage buffer bindings: the materials and lights (common_scene.glsl); the recursed
// reflectors (camera_surface.glsl); the positions, uvs, portals, normals and each
// triangle's material (camera_groups.frag); a shadow volume's caps' codes, read by the
// volume program's vertex stage (volume_caps.glsl; the exact pass checks
// GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS), bound before each draw that reads it, so that it
// may share the normals' binding, which that program does not read; each triangle's object
// and material for scene.vert (triangle_ids.glsl), where the GL offers 10 bindings and 3
// blocks to a vertex stage (GL 4.5's minimums are 8 and 0; llvmpipe and NVIDIA offer more).
constexpr unsigned MATERIALS_BINDING = 0;
constexpr unsigned LIGHTS_BINDING = 1;
constexpr unsigned RECURSED_BINDING = 2;
constexpr unsigned POSITIONS_BINDING = 3;
constexpr unsigned UVS_BINDING = 4;
constexpr unsigned PORTALS_BINDING = 5;
constexpr unsigned NORMALS_BINDING = 6;
constexpr unsigned TRIANGLE_MATERIALS_BINDING = 7;
constexpr unsigned VOLUME_CAPS_BINDING = 6;
constexpr unsigned OBJECT_IDS_BINDING = 8;
constexpr unsigned MATERIAL_IDS_BINDING = 9;

// Storage buffer bindings of the GPU A-buffer's compute passes (gl_abuffer.cpp,
// abuffer_*.comp): after the scene's, so that a build leaves the scene's bindings alone. The
// scan (abuffer_scan.comp) runs on blocks of ABUFFER_SCAN_BLOCK values, one workgroup each.
// Each invocation's work is bounded, because Mesa's llvmpipe ends a shader invocation's loops,
// silently, after 65535 iterations in all (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS): the count
// and fill passes walk a triangle's pixels in tiles of ABUFFER_TILE x ABUFFER_TILE, an
// invocation a tile (64 tiles a workgroup: a small triangle's tile does not hold a workgroup
// of mostly idle invocations), and the finish pass sorts and merges lists of up to
// ABUFFER_GPU_LIST_MAX fragments, leaving longer ones to the CPU's finish
// (finish_fragment_list).
constexpr unsigned ABUFFER_SETUPS_BINDING = 10;
constexpr unsigned ABUFFER_VIEWS_BINDING = 11;
constexpr unsigned ABUFFER_OFFSETS_BINDING = 12;
constexpr unsigned ABUFFER_CURSORS_BINDING = 13;
constexpr unsigned ABUFFER_FRAGMENTS_BINDING = 14;
constexpr unsigned ABUFFER_TRIANGLES_BINDING = 15;
constexpr unsigned ABUFFER_STATS_BINDING = 16;
constexpr unsigned ABUFFER_SCAN_VALUES_BINDING = 17;
constexpr unsigned ABUFFER_SCAN_SUMS_BINDING = 18;
constexpr unsigned ABUFFER_ITEMS_BINDING = 19;
// The GPU's cube walks (gl_cube_walks.cpp, cube_walks.comp): the rays, the texels walked,
// each ray's count, and each ray's first texel in the fill pass.
constexpr unsigned CUBE_WALK_RAYS_BINDING = 20;
constexpr unsigned CUBE_WALK_TEXELS_BINDING = 21;
constexpr unsigned CUBE_WALK_COUNTS_BINDING = 22;
constexpr unsigned CUBE_WALK_OFFSETS_BINDING = 23;
// The GPU's candidate scan (gl_cube_scan.cpp, cube_scan.comp), which reads a batch of walks
// at the two bindings above: the searches' rays, the cube's lists and fragments, the
// triangles' planes, their objects with the restriction rows, the candidates found, and the
// triangles' vertices.
constexpr unsigned CUBE_SCAN_RAYS_BINDING = 24;
constexpr unsigned CUBE_SCAN_LISTS_BINDING = 25;
constexpr unsigned CUBE_SCAN_FRAGMENTS_BINDING = 26;
constexpr unsigned CUBE_SCAN_PLANES_BINDING = 27;
constexpr unsigned CUBE_SCAN_OBJECTS_BINDING = 28;
constexpr unsigned CUBE_SCAN_CANDIDATES_BINDING = 29;
constexpr unsigned CUBE_SCAN_POSITIONS_BINDING = 30;
// The crossing test's pass (cube_refine.comp, mesh_refine.glsl) reads the rays, the
// candidates and the vertices at the bindings above, and the triangles' edge neighbours at
// the lists' binding, which it does not read; the MESH REFINEMENT's bounds are the CPU's.
constexpr unsigned CUBE_REFINE_NEIGHBOURS_BINDING = CUBE_SCAN_LISTS_BINDING;
constexpr unsigned GPU_REFINE_MAX_STEPS = static_cast<unsigned>(REFINE_MAX_STEPS);
constexpr unsigned GPU_REFINE_MAX_TRIANGLES = static_cast<unsigned>(REFINE_MAX_TRIANGLES);
// The scan that walks (cube_scan_walks.comp): its STOP HINT's window (search.hpp), and the
// BLOCK BOUNDS it reads at the walks' offsets binding, which it does not use.
constexpr unsigned GPU_CROSSING_WINDOW_TEXELS = static_cast<unsigned>(CROSSING_WINDOW_TEXELS);
constexpr unsigned CUBE_SCAN_BLOCKS_BINDING = CUBE_WALK_OFFSETS_BINDING;
constexpr int GPU_BOUNDS_BLOCK = SearchContext::BOUNDS_BLOCK;
// THE RESOLVE PLAN on the GPU (gl_resolve_plan.cpp, resolve_plan.comp): the camera's view,
// its lists' offsets and fragments, each triangle's object and opacity, the vertices, each
// pixel's count of steps and status, where each pixel's steps start, and the steps. A
// separate program, so it takes the A-buffer passes' bindings. Each invocation keeps at most
// RESOLVE_STACK items of Pack_Under_Mask's stack; a pixel that needs more is resolved by
// the CPU.
constexpr unsigned RESOLVE_VIEW_BINDING = ABUFFER_VIEWS_BINDING;
constexpr unsigned RESOLVE_LISTS_BINDING = ABUFFER_OFFSETS_BINDING;
constexpr unsigned RESOLVE_FRAGMENTS_BINDING = ABUFFER_FRAGMENTS_BINDING;
constexpr unsigned RESOLVE_TRIANGLES_BINDING = ABUFFER_TRIANGLES_BINDING;
constexpr unsigned RESOLVE_POSITIONS_BINDING = ABUFFER_SETUPS_BINDING;
constexpr unsigned RESOLVE_COUNTS_BINDING = ABUFFER_SCAN_VALUES_BINDING;
constexpr unsigned RESOLVE_STARTS_BINDING = ABUFFER_SCAN_SUMS_BINDING;
constexpr unsigned RESOLVE_STEPS_BINDING = ABUFFER_CURSORS_BINDING;
constexpr unsigned RESOLVE_STACK = 64;
constexpr unsigned ABUFFER_SCAN_BLOCK = 512;
constexpr int ABUFFER_TILE = 8;
constexpr unsigned ABUFFER_GPU_LIST_MAX = 64;

// Image units of the per-group colour pass (camera_groups.frag): the sample grid it blends
// into, and the camera's per-pixel colour and weight.
constexpr unsigned TARGET_IMAGE = 0;
constexpr unsigned PIXEL_COLOR_IMAGE = 1;
constexpr unsigned PIXEL_WEIGHT_IMAGE = 2;

// The #define lines of every constant above and of the sample grid (base/samples.hpp:
// MASK_COLUMNS, MASK_ROWS, MASK_SAMPLES), one a line.
std::string glsl_prelude();

}  // namespace abcube
