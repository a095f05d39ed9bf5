#version 330 core
// Background: a gentle vertical gradient, lighter at the top. Rendered once per
// renderer into a texture; the frame starts as a copy of it and the liquid
// composite reads it, so both agree to the bit.
out vec4 outColor;
uniform vec3 uBackground;
uniform float uGuard;   // guard band [px] around the image
uniform float uHeight;  // image height [px]
void main() {
  float v = (gl_FragCoord.y - uGuard) / uHeight;  // 0 at the image's top (the camera flips y)
  outColor = vec4(uBackground * (0.8 + 0.35 * (1.0 - v)), 1.0);
}
