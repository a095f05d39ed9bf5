#version 330 core
// Composite pass (liquid mode): the splatted field becomes water.
//  - edge: the field thresholded at half its bulk value (lower where the fluid
//    is sparse, so lone drops stay visible), anti-aliased over one pixel;
//  - body: light from above absorbed by the water above the pixel (depth from
//    the CPU grid, scattered sideways on its way down), from the surface colour
//    towards the deep colour;
//  - behind (with SEE_THROUGH: a transmission above 0): what is behind the water
//    (uBg: the background with the solids) seen
//    through it, absorbed per colour channel by the water's thickness
//    (Beer-Lambert: a full layer lets uTransmission through, a thinner one
//    uTransmission^fill) and shifted where that thickness changes (its front face
//    tilts: a thin prism deviates the ray towards the thicker water). The light the
//    water scatters itself is the one that makes a full layer over the plain
//    background (uBgColor) the water's colour: where nothing else is behind, the
//    water looks as its colour says;
//  - surface: shading from the field's gradient (light from above), a bright
//    meniscus just inside the edge and a specular highlight;
//  - foam: towards white where the kernel-weighted speed is high;
//  - with TINT defined (more than one material): the surface colour is the materials' colours
//    weighted by the splat (uTint), the deep colour 0.3 of it.
//  - interior: deep in the water (uAux's G above 1: DepthGrid's deep cells hold 2, a local
//    fill is at most 1) the water is flat: the gradient's tilt, the highlight and the shift of
//    what is behind fade out as G goes from 1 to 2, and the field at the pixel takes the
//    low-passed one's place. With INTERIOR defined the program draws only that: the tiles
//    where G is 2 all over (DepthGrid::tiles), from the centre sample alone, the same colour
//    as the full program there.
// Rows of this target run top-down in the world (the camera flips y). It is
// drawn only over the tiles that fluid can reach (solid.vert: quads in NDC);
// the rest of the frame keeps the background.
out vec4 outColor;
uniform sampler2D uBg;       // the backdrop: background and solids (RGBA8, same size, bilinear)
uniform sampler2D uPlain;    // the background alone: where uBg differs, a solid is behind
uniform sampler2D uField;    // RG: sum w, sum w*speed (full or half resolution, bilinear)
uniform sampler2D uAux;      // RG: depth of water above [m], local fill 0..1 (bilinear)
uniform vec2 uAuxScale;      // vUv -> aux texture coordinates
uniform vec2 uTexel;         // 1 / size
uniform float uInvBulk;      // 1 / field value inside bulk fluid
uniform vec3 uWater;         // colour at the surface
uniform vec3 uDeep;          // colour under deep water
uniform vec3 uFoam;
uniform float uInvDepth;     // 1 / metres of water that darken by 1/e
uniform vec2 uFoamSpeed;     // foam starts, foam full [m/s]
uniform float uSpacingPx;    // particle spacing [px]
uniform float uTapPx;        // the gradient's taps: 0.75 spacing, at least one pixel [px]
uniform vec3 uLogTransmission;  // ln of the share of each channel a full layer lets through
uniform float uRefractPx;    // shift [px] of what is behind per unit of the fill's slope [1/px]
uniform vec3 uBgColor;       // the background's colour (render.background)
#ifdef TINT
uniform sampler2D uTint;     // RGBA: sum w*colour, sum w (the field's resolution, bilinear)
#endif
#ifdef MATERIAL_T
uniform sampler2D uAbsorb;   // RGBA: sum w*ln(transmission), sum w: each material's own
#endif
void main() {
  vec2 vUv = gl_FragCoord.xy * uTexel;
  vec2 c = texture(uField, vUv).rg;
  vec2 aux = texture(uAux, vUv * uAuxScale).rg;
  vec3 bg = texelFetch(uBg, ivec2(gl_FragCoord.xy), 0).rgb;
#ifdef TINT
  vec4 tint = texture(uTint, vUv);
  vec3 surfaceColor = tint.rgb / max(tint.a, 1e-6);
#define SURFACE surfaceColor
#define DEEP (surfaceColor * 0.3)
#else
#define SURFACE uWater
#define DEEP uDeep
#endif
  // Body: Beer-Lambert-like absorption of the light coming from above.
  float absorb = exp(-aux.r * uInvDepth);
  vec3 water = mix(DEEP, SURFACE, absorb);
  vec3 l = vec3(-0.35, 0.8, 0.5);
  l = l / sqrt(dot(l, l));
  float fc = c.r * uInvBulk;  // the field at the pixel, over the bulk's
#ifdef INTERIOR
  // The flat interior: what the full program draws where G is 2 (below): the field at the
  // pixel alone, no tilt, no highlight, what is behind unshifted.
  float cover = 1.0;
  float inside = smoothstep(0.5, 0.95, fc);
  float lambert = 1.0;
  float spec = 0.0;
  float rim = (1.0 - inside) * 0.3;
#ifdef SEE_THROUGH
  vec3 behind = bg;
  float fill = clamp(fc, 0.0, 1.0);
#endif
#else
  float f = fc;
  // Four taps 0.75 spacing away (uTapPx): their central differences give the gradient, and
  // where the fluid is dense they low-pass the field with the centre, so that the surface does
  // not show each particle out of line as a bump; sparse fluid (spray, lone drops) keeps its
  // own field, which the low-pass would take below the edge's threshold.
  vec2 t = uTexel * uTapPx;
  float fl = texture(uField, vUv - vec2(t.x, 0.0)).r * uInvBulk;
  float fr = texture(uField, vUv + vec2(t.x, 0.0)).r * uInvBulk;
  float fa = texture(uField, vUv - vec2(0.0, t.y)).r * uInvBulk;  // world above
  float fb = texture(uField, vUv + vec2(0.0, t.y)).r * uInvBulk;  // world below
  vec2 grad = vec2(fr - fl, fa - fb) * (0.5 / uTapPx);  // per pixel, world orientation (y up)
  float g = length(grad);
  float dense = smoothstep(0.15, 0.55, aux.g);
  f = mix(f, (2.0 * f + fl + fr + fa + fb) / 6.0, dense);
  float threshold = mix(0.24, 0.5, dense);
  // Over a solid the water shows only where the fluid covers it (a body the water flows in
  // front of): the fringe of the field along a body's faces, where the fluid only meets it,
  // leaves the body's edge as it is drawn.
  bool solid = bg != texelFetch(uPlain, ivec2(gl_FragCoord.xy), 0).rgb;
  float cover = clamp((f - (solid ? max(threshold, 0.85) : threshold)) / max(g, 1e-3) + 0.5, 0.0, 1.0);
  // Towards the flat interior (G from 1 to 2): covered, no tilt, highlight or shift, and the
  // field at the pixel instead of the low-passed one.
  float surf = 1.0 - smoothstep(1.0, 2.0, aux.g);
  cover = max(cover, 1.0 - surf);
  if (cover <= 0.0) {
    outColor = vec4(bg, 1.0);
    return;
  }
  grad *= surf;
  float fe = mix(fc, f, surf);
  float inside = smoothstep(threshold, threshold + 0.45, fe);
  // Surface normal from the field: it points out of the fluid (-grad), tilted by the slope.
  vec3 n = vec3(-grad * (6.0 * (1.0 - 0.7 * inside)), 1.0);
  n = n / sqrt(dot(n, n));
  float lambert = 1.0 + 0.55 * (dot(n, l) - l.z);
  vec3 h = l + vec3(0.0, 0.0, 1.0);
  h = h / sqrt(dot(h, h));
  float spec = pow(max(dot(n, h), 0.0), 30.0) * 0.55 * (1.0 - inside) * surf;
  float rim = (1.0 - inside) * 0.3;
#ifdef SEE_THROUGH
  // Behind: the ray bends towards the thicker water (+grad in the world; rows run top-down).
  vec2 seenAt = gl_FragCoord.xy + vec2(grad.x, -grad.y) * uRefractPx;
  vec3 behind = texture(uBg, seenAt * uTexel).rgb;
  float fill = clamp(fe, 0.0, 1.0);
#endif
#endif
#ifdef SEE_THROUGH
#ifdef MATERIAL_T
  vec4 ab = texture(uAbsorb, vUv);
  vec3 logT = ab.rgb / max(ab.a, 1e-6);
#else
  vec3 logT = uLogTransmission;
#endif
  vec3 full = exp(logT);
  vec3 through = exp(logT * fill);
  vec3 scatter = max((water * lambert - full * uBgColor) / max(vec3(1.0) - full, vec3(1e-3)), vec3(0.0));
  water = mix(scatter, behind, through) + vec3(spec) + SURFACE * rim;
#else
  water = water * lambert + vec3(spec) + SURFACE * rim;  // opaque: the colour alone
#endif
  // Foam: fast water, strongest at the surface and in spray.
  float speed = c.g / max(c.r, 1e-6);
  float foam = smoothstep(uFoamSpeed.x, uFoamSpeed.y, speed);
  foam *= mix(1.0, 0.35, inside * smoothstep(0.4, 0.9, aux.g));
  water = mix(water, uFoam, foam * 0.85);
  outColor = vec4(mix(bg, clamp(water, 0.0, 1.0), cover), 1.0);
}
