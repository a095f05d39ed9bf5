#version 330 core
// Particles mode: an anti-aliased disc per particle coloured by its value on a
// blue-cyan-green-yellow-red ramp (the same formula as colorRamp() in image.cpp),
// or (uOwnColor) by its own 0xRRGGBB colour, carried as that integer (exact in a float).
flat in float vValue;    // value mapped to [0, 1] on the CPU, or the colour
in float vWeight;        // age fade (1 without ages)
in vec2 vCorner;
uniform bool uQuads;
uniform bool uOwnColor;
uniform float uRadiusPx; // disc radius [px]
out vec4 outColor;
vec3 ramp(float t) {
  t = clamp(t, 0.0, 1.0);
  return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)), 0.0, 1.0);
}
void main() {
  vec2 d = (uQuads ? vCorner : gl_PointCoord) * 2.0 - 1.0;
  float q = sqrt(dot(d, d));
  float edge = clamp((1.0 - q) * uRadiusPx + 0.5, 0.0, 1.0);
  if (edge <= 0.0) discard;
  // A little relief: lighter towards the upper left, darker at the rim.
  float relief = 1.0 + 0.18 * (-d.x - d.y) * 0.5 - 0.2 * q * q;
  vec3 base;
  if (uOwnColor) {
    uint c = uint(vValue);  // an integer below 2^24, exact in a float and not interpolated (flat)
    base = vec3(float((c >> 16) & 255u), float((c >> 8) & 255u), float(c & 255u)) / 255.0;
  } else {
    base = ramp(vValue);
  }
  outColor = vec4(base * relief, edge * vWeight);
}
