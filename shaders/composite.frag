#version 330 core
// Composite pass: threshold the splatted field into a liquid with a smooth,
// anti-aliased edge; shade it from the field's gradient (light from above),
// colour it by thickness, and lighten the rim.
in vec2 vUv;
out vec4 outColor;
uniform sampler2D uField;
uniform vec2 uTexel;        // 1 / size
uniform float uInvBulk;     // 1 / field value inside bulk fluid
uniform vec3 uBackground;
uniform vec3 uWater;
uniform float uEdgePixels;  // width of the anti-aliased edge in field units per pixel
void main() {
  float f  = texture(uField, vUv).r * uInvBulk;
  float fl = texture(uField, vUv - vec2(uTexel.x, 0.0)).r * uInvBulk;
  float fr = texture(uField, vUv + vec2(uTexel.x, 0.0)).r * uInvBulk;
  float fd = texture(uField, vUv - vec2(0.0, uTexel.y)).r * uInvBulk;
  float fu = texture(uField, vUv + vec2(0.0, uTexel.y)).r * uInvBulk;
  // Rows run top-down in this target (the camera flips y), so +v is world down.
  vec2 grad = vec2(fr - fl, fd - fu) * 0.5;
  float g = length(grad);
  // Anti-aliased threshold at f = 0.5: the edge spans about one pixel.
  float w = max(g * 1.2, 1e-4);
  float cover = smoothstep(0.5 - w, 0.5 + w, f);
  // Background: a gentle vertical gradient.
  vec3 bg = uBackground * (0.85 + 0.3 * (1.0 - vUv.y));
  // Water: deeper colour where the field is thick, light from above on the surface.
  float depth = smoothstep(0.6, 1.6, f);
  vec3 shallow = mix(uWater, vec3(1.0), 0.35);
  vec3 deep = uWater * 0.55;
  vec3 water = mix(shallow, deep, depth);
  vec3 n = normalize(vec3(-grad.x * 6.0, -grad.y * 6.0, 1.0));
  vec3 l = normalize(vec3(-0.3, 0.8, 0.6));
  float diffuse = 0.75 + 0.35 * dot(n, l);
  float spec = pow(max(dot(reflect(-l, n), vec3(0.0, 0.0, 1.0)), 0.0), 24.0) * 0.6;
  float rim = 1.0 - smoothstep(0.5, 0.8, f);
  water = water * diffuse + vec3(spec) + vec3(0.35) * rim;
  outColor = vec4(mix(bg, clamp(water, 0.0, 1.0), cover), 1.0);
}
