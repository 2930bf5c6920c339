// Each triangle's object and material, read at the drawn vertex's triangle (gl_VertexID / 3:
// the scene's vertex arrays hold 3 vertices a triangle, drawn as they are or by index) from
// the soup's own per-triangle arrays (gl_scene_buffers.cpp), instead of 8 bytes of attributes a
// vertex. Prepended to scene.vert where the GL gives its vertex stage enough storage buffers
// (glsl_shared.hpp OBJECT_IDS_BINDING, MATERIAL_IDS_BINDING); elsewhere each vertex
// carries its ids as attributes 2 and 3.
#define TRIANGLE_IDS 1
layout(std430, binding = OBJECT_IDS_BINDING) readonly buffer ObjectIds { uint object_ids[]; };
layout(std430, binding = MATERIAL_IDS_BINDING) readonly buffer MaterialIds { uint material_ids[]; };
uniform bool u_vertex_ids;  // this draw's vertices carry their own ids (the faces at infinity)
