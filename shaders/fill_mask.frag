// Clears the stencilled region of the shadow-volume mask (an unsigned integer target).
layout(location = 0) out uvec4 o_mask;

void main() { o_mask = uvec4(0u); }
