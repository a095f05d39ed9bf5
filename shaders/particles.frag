#version 330 core
// Particles mode: a disc per particle coloured by its value on a blue-to-red ramp.
in float vValue;         // value normalised to [0, 1] on the CPU
out vec4 outColor;
vec3 ramp(float t) {
  t = clamp(t, 0.0, 1.0);
  return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)), 0.0, 1.0);
}
void main() {
  vec2 d = gl_PointCoord * 2.0 - 1.0;
  float q2 = dot(d, d);
  if (q2 >= 1.0) discard;
  outColor = vec4(ramp(vValue) * (1.0 - 0.25 * q2), 1.0);
}
