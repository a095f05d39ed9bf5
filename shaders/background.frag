#version 330 core
// Background: a gentle vertical gradient, lighter at the top. Rendered once per
// renderer into a texture; the frame starts as a copy of it and the liquid
// composite reads it, so both agree to the bit.
out vec4 outColor;
uniform vec3 uBackground;
uniform float uGuard;   // guard band [px] around the image
uniform float uHeight;  // image height [px]
// render.tiles: x of the targets' left edge and y of their top [m], metres per pixel, the
// tiles' side [m] (0: none). The tiles' joints are lighter lines about 2 px wide.
uniform vec4 uTiles;
void main() {
  float v = (gl_FragCoord.y - uGuard) / uHeight;  // 0 at the image's top (the camera flips y)
  vec3 c = uBackground * (0.8 + 0.35 * (1.0 - v));
  if (uTiles.w > 0.0) {
    vec2 w = vec2(uTiles.x + gl_FragCoord.x * uTiles.z, uTiles.y - gl_FragCoord.y * uTiles.z);
    vec2 t = w / uTiles.w;
    vec2 px = abs(t - floor(t + 0.5)) * (uTiles.w / uTiles.z);  // pixels to the nearest joint
    c += vec3(0.09, 0.10, 0.11) * (1.0 - smoothstep(0.5, 1.5, min(px.x, px.y)));
  }
  outColor = vec4(c, 1.0);
}
