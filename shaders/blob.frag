#version 330 core
// Blob pass (liquid mode, particle groups): the groups' particles, splatted like the water but
// into a target of their own (tint.frag: RGB = sum of w * colour, A = sum of w), become solid
// blobs drawn over the water:
//  - edge: the field cut at 0.4 of its bulk value (the water's cut is 0.5 where it is dense, so
//    a blob in water covers the water's edge round the hole it leaves), anti-aliased over one
//    pixel by the distance to the cut (field over its gradient);
//  - fill: the group's colour (the weighted mean where two groups touch), lit from the upper
//    left by the field's gradient, so it reads as a rounded solid, not as paint;
//  - outline: the colour at 0.45 over a band uOutlinePx wide inside the edge, also where the
//    blob meets water (the water's field does not count in this one).
// Drawn over the tiles the fluid can reach (solid.vert), blended by the edge's cover.
out vec4 outColor;
uniform sampler2D uBlob;    // RGBA: sum w*colour, sum w (the field's resolution, bilinear)
uniform vec2 uTexel;        // 1 / size
uniform float uInvBulk;     // 1 / field value inside a bulk of particles
uniform float uOutlinePx;   // outline width [px]
void main() {
  vec2 uv = gl_FragCoord.xy * uTexel;
  vec4 b = texture(uBlob, uv);
  float f = b.a * uInvBulk;
  float fl = texture(uBlob, uv - vec2(uTexel.x, 0.0)).a * uInvBulk;
  float fr = texture(uBlob, uv + vec2(uTexel.x, 0.0)).a * uInvBulk;
  float fa = texture(uBlob, uv - vec2(0.0, uTexel.y)).a * uInvBulk;  // world above
  float fb = texture(uBlob, uv + vec2(0.0, uTexel.y)).a * uInvBulk;  // world below
  vec2 grad = vec2(fr - fl, fa - fb) * 0.5;  // per pixel, world orientation (y up)
  float d = (f - 0.4) / max(length(grad), 1e-3);  // pixels inside the edge
  float cover = clamp(d + 0.5, 0.0, 1.0);
  if (cover <= 0.0) discard;
  vec3 fill = b.rgb / max(b.a, 1e-6);
  vec3 n = vec3(-grad * 4.0, 1.0);
  n = n / sqrt(dot(n, n));
  vec3 l = vec3(-0.35, 0.8, 0.5);
  l = l / sqrt(dot(l, l));
  vec3 lit = fill * (1.0 + 0.5 * (dot(n, l) - l.z));
  float line = 1.0 - clamp(d - uOutlinePx + 0.5, 0.0, 1.0);  // 1 within the outline's band
  outColor = vec4(clamp(mix(lit, fill * 0.45, line), 0.0, 1.0), cover);
}
