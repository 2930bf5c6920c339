// Fills the stencilled region of a float target (a mirror's region cleared to the
// background, a shadow count cleared to 0).
uniform vec4 u_fill;
layout(location = 0) out vec4 o_color;

void main() { o_color = u_fill; }
