// The renderer in a game's own OpenGL context (Renderer(currentGlContext, ...), draw()).
//
// Each test plays the game: it makes its own OSMesa context (3.3 core, as the Renderer's own;
// one test a compatibility-profile one), its own framebuffer with a depth buffer, program,
// vertex array, textures and samplers, sets state far from GL's defaults, and draws a World
// through the renderer. The tests assert, with the game's own queries and readbacks:
//  - every state item the game set (and a few the renderer never touches) is exactly as before;
//  - the game's framebuffer holds the very pixels the OSMesa path reads back for the same World
//    (equal bytes: the frame is drawn at its own size, where the presentation copies texels;
//    the liquid and particles modes, solids, a floating crate and a turning paddle);
//  - pixels outside the viewport keep what the game drew; a scaled viewport still shows water;
//  - bad use is refused with a message that says what is wrong, and the state is still restored.
// Where the game's state would change the frame (a sampler that filters with mipmaps on the
// units the composite reads, scissor, blending, culling, line polygons, colour masks, logic op,
// rasterizer discard, a bound pixel-unpack buffer, odd unpack parameters, a depth buffer cleared
// to 0 with the depth test on), an item the renderer forgot to set fails the pixel check, and one
// it forgot to restore fails the state check.
#include "render_context_game.hpp"

using namespace sph2d;
using namespace rctest;

TEST_CASE(
    "draw() into the game's framebuffer: every piece of GL state the game set is given back and the pixels are the OSMesa path's") {
  // "liquid/gl": the splat by the GL's point sprites (a hardware GL's default; llvmpipe's is the CPU's).
  for (const std::string path : {"liquid", "liquid/gl", "particles"}) {
    CAPTURE(path);
    const std::string mode = path.substr(0, path.find('/'));
    const SceneDef s = gameScene(mode);
    RenderOptions o = optionsFor(mode);
    if (path == "liquid/gl") o.splat = SplatPath::Gl;
    const auto world = steppedWorld(s, 12);
    REQUIRE(world->movingColliders().size() == 2);  // the crate and the paddle are drawn too
    const std::vector<unsigned char> reference = osmesaFrame(*world, s, o);

    GameContext game;
    GameObjects g;
    Renderer renderer(currentGlContext, s.render, o);
    CHECK(renderer.usesCurrentContext());
    CHECK(renderer.splatPath() == (mode == "particles" ? "" : path == "liquid/gl" ? "gl" : "cpu"));
    setGameState(g);
    const std::vector<Item> before = snapshot();
    renderer.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, W, H}});
    CHECK(glGetError() == GL_NO_ERROR);  // nothing left pending
    checkSame(before, snapshot());

    // The frame, exactly: the game reads its framebuffer back (rows bottom-up) and flips it.
    const std::vector<unsigned char> drawn = flipRows(g.pixels(), W, H);
    const std::size_t diff = differing(drawn, reference);
    MESSAGE(mode << ": " << diff << " of " << W * H << " pixels differ from the OSMesa path's frame");
    CHECK(diff == 0);
    CHECK(xxh64(drawn.data(), drawn.size()) == xxh64(reference.data(), reference.size()));
    if (mode == "liquid") CHECK(waterShare(drawn) > 0.15);
    // Drawn with the depth test off: the game's depth buffer (cleared to 0) is untouched.
    const std::vector<float> depth = g.depth();
    CHECK(std::count(depth.begin(), depth.end(), 0.0f) == std::ptrdiff_t(depth.size()));
    CHECK(renderer.lastTimings().present > 0);
    CHECK(renderer.lastTimings().readback == 0);  // no readback
  }
}

TEST_CASE("draw() over a sub-viewport leaves every pixel outside it as the game drew it") {
  const SceneDef s = gameScene("liquid");
  const auto world = steppedWorld(s, 12);
  const std::vector<unsigned char> reference = osmesaFrame(*world, s, {});
  GameContext game;
  const int FW = W + 50, FH = H + 40;
  GameObjects g(FW, FH);
  const std::vector<unsigned char> gameDrawing = g.pixels();
  Renderer renderer(currentGlContext, s.render);

  SUBCASE("at the frame's size, through the bound framebuffer and the current viewport (the default target)") {
    const int X = 21, Y = 13;
    setGameState(g);
    glViewport(X, Y, W, H);
    const std::vector<Item> before = snapshot();
    renderer.draw(*world);
    checkSame(before, snapshot());
    const std::vector<unsigned char> after = g.pixels();
    std::size_t outsideChanged = 0, insideDiffer = 0;
    for (int y = 0; y < FH; ++y)
      for (int x = 0; x < FW; ++x) {
        const std::size_t p = (std::size_t(y) * FW + std::size_t(x)) * 4;
        const bool inside = x >= X && x < X + W && y >= Y && y < Y + H;
        // inside: the reference's pixel at (x − X, row from the top)
        const std::size_t r = (std::size_t(H - 1 - (y - Y)) * W + std::size_t(x - X)) * 4;
        const bool same = inside ? std::equal(after.begin() + std::ptrdiff_t(p), after.begin() + std::ptrdiff_t(p + 4),
                                              reference.begin() + std::ptrdiff_t(r))
                                 : std::equal(after.begin() + std::ptrdiff_t(p), after.begin() + std::ptrdiff_t(p + 4),
                                              gameDrawing.begin() + std::ptrdiff_t(p));
        (inside ? insideDiffer : outsideChanged) += !same;
      }
    CHECK(outsideChanged == 0);
    CHECK(insideDiffer == 0);
  }
  SUBCASE("scaled to half the frame's size: outside untouched, water inside") {
    const int X = 30, Y = 25, VW = W / 2, VH = H / 2;
    setGameState(g);
    const std::vector<Item> before = snapshot();
    renderer.draw(*world, GlTarget{std::nullopt, std::array<int, 4>{X, Y, VW, VH}});
    checkSame(before, snapshot());
    const std::vector<unsigned char> after = g.pixels();
    std::size_t outsideChanged = 0;
    std::vector<unsigned char> inside;
    for (int y = 0; y < FH; ++y)
      for (int x = 0; x < FW; ++x) {
        const std::size_t p = (std::size_t(y) * FW + std::size_t(x)) * 4;
        if (x >= X && x < X + VW && y >= Y && y < Y + VH)
          inside.insert(inside.end(), after.begin() + std::ptrdiff_t(p), after.begin() + std::ptrdiff_t(p + 4));
        else
          outsideChanged += !std::equal(after.begin() + std::ptrdiff_t(p), after.begin() + std::ptrdiff_t(p + 4),
                                        gameDrawing.begin() + std::ptrdiff_t(p));
      }
    CHECK(outsideChanged == 0);
    const double full = waterShare(reference), half = waterShare(inside);
    MESSAGE("water: " << full << " of the frame, " << half << " of the half-size viewport");
    CHECK(half == doctest::Approx(full).epsilon(0.1));
    // The water is at the bottom of the viewport (GL rows: the world's bottom is row 0); a
    // quarter up is 0.15 m above the floor, the top row 1.05 m.
    const std::vector<unsigned char> lowRow(inside.begin() + std::ptrdiff_t(VW * 4 * (VH / 4)),
                                            inside.begin() + std::ptrdiff_t(VW * 4 * (VH / 4 + 1)));
    const std::vector<unsigned char> highRow(inside.begin() + std::ptrdiff_t(VW * 4 * (VH - 2)),
                                             inside.begin() + std::ptrdiff_t(VW * 4 * (VH - 1)));
    CHECK(waterShare(lowRow) > 0.5);
    CHECK(waterShare(highRow) == 0);
  }
}

TEST_CASE(
    "draw() into the default framebuffer (the game's window) at a viewport: the OSMesa path's pixels there and the window's own elsewhere") {
  const SceneDef s = gameScene("particles", W, H);
  const RenderOptions o = optionsFor("particles");
  const auto world = steppedWorld(s, 12);
  const std::vector<unsigned char> reference = osmesaFrame(*world, s, o);
  const int WW = W + 30, WH = H + 20, X = 12, Y = 9;
  GameContext game(false, WW, WH);
  glClearColor(0.3f, 0.3f, 0.1f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);  // the game's drawing in its window
  auto readWindow = [&](int x, int y, int w, int h) { return readRgba(0, x, y, w, h); };
  const std::vector<unsigned char> gameDrawing = readWindow(0, 0, WW, WH);
  GameObjects g;
  Renderer renderer(currentGlContext, s.render, o);
  setGameState(g);
  const std::vector<Item> before = snapshot();
  renderer.draw(*world, GlTarget{0u, std::array<int, 4>{X, Y, W, H}});
  checkSame(before, snapshot());
  CHECK(differing(flipRows(readWindow(X, Y, W, H), W, H), reference) == 0);
  const std::vector<unsigned char> win = readWindow(0, 0, WW, WH);
  std::size_t outsideChanged = 0;
  for (int y = 0; y < WH; ++y)
    for (int x = 0; x < WW; ++x) {
      if (x >= X && x < X + W && y >= Y && y < Y + H) continue;
      const std::size_t p = (std::size_t(y) * WW + std::size_t(x)) * 4;
      outsideChanged += !std::equal(&win[p], &win[p] + 4, &gameDrawing[p]);
    }
  CHECK(outsideChanged == 0);
  CHECK(std::count(gameDrawing.begin(), gameDrawing.end(), 0) == 0);  // the clear colour, not OSMesa's zeros
}

TEST_CASE(
    "draw() frame after frame with a floating crate and a turning paddle, interleaved with the OSMesa path: the same pixels every frame") {
  const SceneDef s = gameScene("liquid");
  auto world = steppedWorld(s, 2);
  Renderer own(s.render);  // the OSMesa path, alive beside the game's context
  GameContext game;
  GameObjects g;
  Renderer renderer(currentGlContext, s.render);
  std::vector<std::uint64_t> hashes;
  for (int k = 0; k < 5; ++k) {
    for (int f = 0; f < 4; ++f) world->stepFrame();
    const std::vector<unsigned char> reference = own.render(*world).rgba;  // makes its own context current
    game.makeCurrent();
    setGameState(g);
    const std::vector<Item> before = snapshot();
    renderer.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, W, H}});
    checkSame(before, snapshot());
    const std::vector<unsigned char> drawn = flipRows(g.pixels(), W, H);
    CHECK_MESSAGE(differing(drawn, reference) == 0, "frame " << world->frame());
    hashes.push_back(xxh64(drawn.data(), drawn.size()));
  }
  std::sort(hashes.begin(), hashes.end());
  CHECK(std::unique(hashes.begin(), hashes.end()) == hashes.end());  // the paddle turns: every frame differs
}

TEST_CASE(
    "render() in the game's context reads back the OSMesa path's frame (overlay and colour bar included) and gives the state back") {
  SceneDef s = gameScene("particles");
  RenderOptions o;  // colour by speed: a colour bar
  o.overlay = true;
  const auto world = steppedWorld(s, 12);
  const std::vector<unsigned char> reference = osmesaFrame(*world, s, o);
  GameContext game;
  GameObjects g;
  const std::vector<unsigned char> gameDrawing = g.pixels();
  Renderer renderer(currentGlContext, s.render, o);
  setGameState(g);
  const std::vector<Item> before = snapshot();
  const Frame& frame = renderer.render(*world);
  checkSame(before, snapshot());
  CHECK(differing(frame.rgba, reference) == 0);
  CHECK(differing(g.pixels(), gameDrawing) == 0);  // render() leaves the game's framebuffer alone
  CHECK(renderer.lastTimings().readback > 0);
}

TEST_CASE(
    "draw() in a compatibility-profile context: the game's alpha test, point sprites off, colour clamping, polygon stipple and pixel transfer change nothing and are given back") {
  for (const std::string path : {"liquid", "liquid/gl", "particles"}) {  // liquid/gl: the GL's point sprites
    CAPTURE(path);
    const std::string mode = path.substr(0, path.find('/'));
    const SceneDef s = gameScene(mode);
    RenderOptions o = optionsFor(mode);
    if (path == "liquid/gl") o.splat = SplatPath::Gl;
    const auto world = steppedWorld(s, 12);
    const std::vector<unsigned char> reference = osmesaFrame(*world, s, o);
    GameContext game(true);
    GLint mask = 0;
    glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
    REQUIRE((mask & GL_CONTEXT_COMPATIBILITY_PROFILE_BIT) != 0);
    GameObjects g;
    Renderer renderer(currentGlContext, s.render, o);
    setGameState(g, true);
    const std::vector<Item> before = snapshot(true);
    renderer.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, W, H}});
    CHECK(glGetError() == GL_NO_ERROR);
    checkSame(before, snapshot(true));
    // The game's pixel transfer would change the game's own readback too: plain for reading.
    glPixelTransferf(GL_RED_SCALE, 1.0f);
    glPixelTransferf(GL_GREEN_BIAS, 0.0f);
    CHECK(differing(flipRows(g.pixels(), W, H), reference) == 0);
  }
}

TEST_CASE("the renderer on the game's context refuses bad use with a clear error and gives the state back") {
  const SceneDef s = gameScene("liquid");
  const auto world = steppedWorld(s, 2);
  {
    Renderer own(s.render);
    CHECK_FALSE(own.usesCurrentContext());
    CHECK_THROWS_WITH_AS(own.draw(*world), doctest::Contains("OSMesa context of its own"), std::logic_error);
  }
  GameContext game;
  GameObjects g;
  Renderer renderer(currentGlContext, s.render);
  setGameState(g);
  const std::vector<Item> before = snapshot();

  // Not a framebuffer, an empty viewport, an incomplete framebuffer.
  CHECK_THROWS_WITH_AS(renderer.draw(*world, GlTarget{4242u, std::nullopt}),
                       doctest::Contains("4242 is not a framebuffer object"), std::invalid_argument);
  CHECK_THROWS_WITH_AS(renderer.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, 0, 10}}),
                       doctest::Contains("viewport is empty"), std::invalid_argument);
  GLuint empty = 0;
  glGenFramebuffers(1, &empty);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, empty);  // made a framebuffer, without attachments
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, g.fbo);
  CHECK_THROWS_WITH_AS(renderer.draw(*world, GlTarget{empty, std::nullopt}), doctest::Contains("is not complete"),
                       std::runtime_error);
  CHECK(glGetError() == GL_NO_ERROR);
  checkSame(before, snapshot());  // also after a throw from the middle of a frame

  // An error of the game's, pending: reported (glGetError has taken it), nothing drawn.
  const std::vector<unsigned char> pixelsBefore = g.pixels();
  setGameState(g);
  glEnable(GLenum(0x1234));  // GL_INVALID_ENUM
  CHECK_THROWS_WITH_AS(renderer.draw(*world), doctest::Contains("an OpenGL error (0x500) was pending"),
                       std::runtime_error);
  CHECK(glGetError() == GL_NO_ERROR);
  checkSame(before, snapshot());
  CHECK(differing(g.pixels(), pixelsBefore) == 0);

  // No context current: construction and drawing say so.
  REQUIRE(OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0));
  CHECK_THROWS_WITH_AS(Renderer(currentGlContext, s.render), doctest::Contains("no OpenGL context is current"),
                       std::runtime_error);
  CHECK_THROWS_WITH_AS(renderer.draw(*world), doctest::Contains("no OpenGL context is current"), std::runtime_error);
  game.makeCurrent();
  glDeleteFramebuffers(1, &empty);
}

TEST_CASE(
    "draw() into a framebuffer with two colour attachments writes the first and leaves the second as the game drew it") {
  const SceneDef s = gameScene("liquid");
  const RenderOptions o = optionsFor("liquid");
  const auto world = steppedWorld(s, 12);
  const std::vector<unsigned char> reference = osmesaFrame(*world, s, o);
  GameContext game;
  GameObjects g;
  // A second colour attachment (the game's G-buffer, say), cleared to one colour, both drawn to.
  GLuint second = 0;
  glGenTextures(1, &second);
  glBindTexture(GL_TEXTURE_2D, second);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, W, H, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  glBindFramebuffer(GL_FRAMEBUFFER, g.fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, second, 0);
  const GLenum both[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glDrawBuffers(2, both);
  const GLfloat teal[4] = {0.0f, 0.5f, 0.5f, 1.0f};
  glClearBufferfv(GL_COLOR, 1, teal);
  REQUIRE(glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);
  auto readSecond = [&] {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, g.fbo);
    glReadBuffer(GL_COLOR_ATTACHMENT1);
    std::vector<unsigned char> p = readRgba(g.fbo, 0, 0, W, H);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    return p;
  };
  const std::vector<unsigned char> secondBefore = readSecond();
  REQUIRE(secondBefore[1] == 128);  // teal
  Renderer renderer(currentGlContext, s.render, o);
  glBindFramebuffer(GL_FRAMEBUFFER, g.fbo);
  renderer.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, W, H}});
  CHECK(glGetError() == GL_NO_ERROR);
  CHECK(differing(readSecond(), secondBefore) == 0);
  CHECK(differing(flipRows(g.pixels(), W, H), reference) == 0);
  glDeleteTextures(1, &second);
}

TEST_CASE(
    "another context current (an OSMesa renderer's) is refused by draw(), and destroying the game's renderer there leaves that context's objects alone") {
  const SceneDef s = gameScene("liquid");
  const auto world = steppedWorld(s, 6);
  GameContext game;
  auto mine = std::make_unique<Renderer>(currentGlContext, s.render);
  Renderer screenshots(s.render);  // an OSMesa renderer: render() leaves its own context current
  const std::uint64_t first = xxh64(screenshots.render(*world).rgba.data(), screenshots.render(*world).rgba.size());
  CHECK_THROWS_WITH_AS(mine->draw(*world), doctest::Contains("another OpenGL context is current"), std::runtime_error);
  mine.reset();  // in the OSMesa renderer's context: must not delete objects by our names there
  const Frame& again = screenshots.render(*world);
  CHECK(xxh64(again.rgba.data(), again.rgba.size()) == first);
  game.makeCurrent();
  Renderer back(currentGlContext, s.render);
  GameObjects g;
  back.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, W, H}});
  CHECK(glGetError() == GL_NO_ERROR);
}

TEST_CASE("a context below OpenGL 3.3 is refused naming the version found") {
  if (!isChild()) {
    const apptest::Result r =
        runChild("a context below OpenGL 3.3 is refused naming the version found", "MESA_GL_VERSION_OVERRIDE=2.1");
    INFO(r.out);
    CHECK(r.code == 0);
    CHECK(r.out.find("child: refused: ") != std::string::npos);
    return;
  }
  GameContext game(true);  // compatibility profile, reported as 2.1 by the override
  const std::string version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  REQUIRE(version.rfind("2.1", 0) == 0);
  try {
    Renderer renderer(currentGlContext, gameScene("liquid").render);
    FAIL("a 2.1 context was accepted");
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    CHECK(what.find("needs OpenGL 3.3 or later") != std::string::npos);
    CHECK(what.find("is OpenGL 2.1 Mesa") != std::string::npos);
    std::printf("child: refused: %s\n", e.what());
  }
  CHECK(glGetError() == GL_NO_ERROR);
}

TEST_CASE("an OpenGL 3.3 core context without GL_ARB_copy_image gets the same pixels (background rows blitted)") {
  const char* name =
      "an OpenGL 3.3 core context without GL_ARB_copy_image gets the same pixels (background rows blitted)";
  const SceneDef s = gameScene("liquid");
  const auto world = steppedWorld(s, 12);
  if (!isChild()) {
    const std::vector<unsigned char> reference = osmesaFrame(*world, s, {});  // glCopyImageSubData here
    const apptest::Result r = runChild(name,
                                       "MESA_GL_VERSION_OVERRIDE=3.3 MESA_EXTENSION_OVERRIDE=-GL_ARB_copy_image "
                                       "SPH2D_EXPECT_RGBA_XXH64=" +
                                           hex64(xxh64(reference.data(), reference.size())));
    INFO(r.out);
    CHECK(r.code == 0);
    CHECK(r.out.find("child: 3.3 without GL_ARB_copy_image: same pixels") != std::string::npos);
    return;
  }
  GameContext game;
  const std::string version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  REQUIRE(version.rfind("3.3", 0) == 0);
  GLint n = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &n);
  for (GLint i = 0; i < n; ++i)
    REQUIRE(std::string(reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, GLuint(i)))) != "GL_ARB_copy_image");
  GameObjects g;
  Renderer renderer(currentGlContext, s.render);
  const char* expected = std::getenv("SPH2D_EXPECT_RGBA_XXH64");
  REQUIRE(expected);
  for (int k = 0; k < 2; ++k) {  // the second frame restores only the rows the first one changed
    setGameState(g);
    const std::vector<Item> before = snapshot();
    renderer.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, W, H}});
    CHECK(glGetError() == GL_NO_ERROR);
    checkSame(before, snapshot());
    const std::vector<unsigned char> drawn = flipRows(g.pixels(), W, H);
    CHECK(hex64(xxh64(drawn.data(), drawn.size())) == expected);
  }
  std::printf("child: 3.3 without GL_ARB_copy_image: same pixels\n");
}
