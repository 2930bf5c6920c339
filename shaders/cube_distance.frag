// Distance prepass: Euclidean distance from the eye (not window z), and the object id.
in vec3 v_relative;
in vec3 v_normal;
flat in uint v_object;
flat in uint v_material;

layout(location = 0) out float o_distance;
layout(location = 1) out uint o_object;

void main() {
  o_distance = length(v_relative);
  o_object = v_object;
}
