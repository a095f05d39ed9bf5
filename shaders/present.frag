#version 330 core
// Presentation (draws into the caller's context): the finished frame, from the Renderer's
// colour target, into the caller's framebuffer over its viewport. The target holds the image
// inside a guard band, rows top-down in the world; the caller's framebuffer has GL's rows,
// bottom-up, so the world's top lands at the viewport's top. At the image's own size each pixel
// is one texel, copied exactly; at any other size the image is sampled bilinearly.
uniform sampler2D uFrame;   // the colour target (RGBA8): image + guard band
uniform ivec4 uViewport;    // x, y, width, height of the caller's viewport [px]
uniform ivec3 uImage;       // guard band, image width, image height [px]
out vec4 outColor;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy) - uViewport.xy;  // pixel of the viewport, from its lower left
  if (uViewport.zw == uImage.yz) {
    outColor = texelFetch(uFrame, ivec2(uImage.x + p.x, uImage.x + uImage.z - 1 - p.y), 0);
  } else {
    vec2 uv = (gl_FragCoord.xy - vec2(uViewport.xy)) / vec2(uViewport.zw);  // 0..1 over the viewport
    vec2 t = vec2(float(uImage.x) + uv.x * float(uImage.y), float(uImage.x) + (1.0 - uv.y) * float(uImage.z));
    outColor = texture(uFrame, t / vec2(textureSize(uFrame, 0)));
  }
}
