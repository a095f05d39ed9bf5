#version 330 core
// Splat pass: one point sprite per particle, positioned by the camera transform.
layout(location = 0) in vec2 aPos;     // particle position, engine local frame [m]
layout(location = 1) in float aValue;  // per-particle value (speed), used by the particles mode
uniform vec2 uScale;                   // local frame -> NDC scale
uniform vec2 uOffset;                  // local frame -> NDC offset
uniform float uPointSize;              // sprite diameter [px]
out float vValue;
void main() {
  gl_Position = vec4(aPos * uScale + uOffset, 0.0, 1.0);
  gl_PointSize = uPointSize;
  vValue = aValue;
}
