#version 330 core
// Splat pass: a soft, compact kernel w = (1 - q^2)^3 (times the age fade) added
// into an RG32F target: R = sum of w, G = sum of w * speed (foam).
flat in float vValue;
in float vWeight;
in vec2 vCorner;
uniform bool uQuads;
out vec2 outField;
void main() {
  vec2 d = (uQuads ? vCorner : gl_PointCoord) * 2.0 - 1.0;
  float q2 = dot(d, d);
  if (q2 >= 1.0) discard;
  float a = 1.0 - q2;
  float w = a * a * a * vWeight;
  outField = vec2(w, w * vValue);
}
