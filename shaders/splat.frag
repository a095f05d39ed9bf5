#version 330 core
// Splat pass: a soft, compact kernel (1 - q^2)^3 added into an R32F target.
in float vValue;
out float outField;
void main() {
  vec2 d = gl_PointCoord * 2.0 - 1.0;
  float q2 = dot(d, d);
  if (q2 >= 1.0) discard;
  float a = 1.0 - q2;
  outField = a * a * a;
}
