#version 330 core
// Sprite vertex shader of the splat pass (liquid) and the discs (particles mode).
// Points: one vertex per particle, gl_PointSize = diameter. Quads: when the
// diameter exceeds the driver's point-size limit, four corners per instance.
layout(location = 0) in vec2 aPos;     // particle position, engine local frame [m]
layout(location = 1) in float aValue;  // liquid: speed [m/s]; particles: value mapped to 0..1
layout(location = 2) in float aWeight; // 1, or the age fade of the particle
layout(location = 3) in vec2 aCorner;  // quads only: corner in [-1, 1]^2
uniform vec2 uScale;                   // local frame -> NDC scale
uniform vec2 uOffset;                  // local frame -> NDC offset
uniform float uPointSize;              // sprite diameter [px] (points)
uniform bool uQuads;                   // draw instanced quads instead of points
uniform vec2 uHalfNdc;                 // quads: half the diameter in NDC (x, y)
flat out float vValue;                 // one value per sprite (exact: a colour is an integer)
out float vWeight;
out vec2 vCorner;                      // quads: the sprite coordinate, like gl_PointCoord
void main() {
  vec2 c = aPos * uScale + uOffset;
  if (uQuads) {
    gl_Position = vec4(c + aCorner * uHalfNdc, 0.0, 1.0);
    vCorner = aCorner * 0.5 + 0.5;
    gl_PointSize = 1.0;
  } else {
    gl_Position = vec4(c, 0.0, 1.0);
    vCorner = vec2(0.5);
    gl_PointSize = uPointSize;
  }
  vValue = aValue;
  vWeight = aWeight;
}
