#version 330 core
// Tint pass (liquid mode, more than one material): each particle's material colour weighted by
// the splat's kernel w = (1 - q^2)^3 (times the age fade), added into an RGBA32F target:
// RGB = sum of w * colour, A = sum of w. The composite divides: the colour of the fluid there.
flat in float vValue;  // the material's colour 0xRRGGBB (an integer below 2^24: exact in a float)
in float vWeight;
in vec2 vCorner;
uniform bool uQuads;
out vec4 outTint;
// With ABSORB: the value is the material's transmission, 8 bits a channel as the colour is, and
// the target gets RGB = sum of w * ln(transmission) (the composite divides: Beer-Lambert's
// exponent per unit of thickness where materials meet, the thickness-weighted mean).
void main() {
  vec2 d = (uQuads ? vCorner : gl_PointCoord) * 2.0 - 1.0;
  float q2 = dot(d, d);
  if (q2 >= 1.0) discard;
  float a = 1.0 - q2;
  float w = a * a * a * vWeight;
  uint c = uint(vValue);
  vec3 rgb = vec3(float((c >> 16) & 255u), float((c >> 8) & 255u), float(c & 255u)) / 255.0;
#ifdef ABSORB
  outTint = vec4(w * log(max(rgb, vec3(1e-3))), w);
#else
  outTint = vec4(w * rgb, w);
#endif
}
