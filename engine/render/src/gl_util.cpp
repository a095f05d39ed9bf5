// gl_util.cpp — shader compilation, programs, textures and framebuffers (see gl_util.hpp).
#include "gl_util.hpp"

#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace sph2d {

const std::map<std::string, std::string>& embeddedShaders();

namespace gl {
namespace {

/// Compiles shaders/`name`, with `defines` ("#define X\n" lines) after its #version line.
GLuint compile(GLenum type, const std::string& name, const std::string& defines = "") {
  std::string src = shaderSource(name);
  if (!defines.empty()) src.insert(src.find('\n') + 1, defines);
  GLuint s = glCreateShader(type);
  const char* p = src.c_str();
  glShaderSource(s, 1, &p, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    throw std::runtime_error("shader " + name + " does not compile: " + log);
  }
  return s;
}

}  // namespace

std::string shaderSource(const std::string& name) {
  if (const char* dir = std::getenv("SPH2D_SHADER_DIR")) {
    std::ifstream in(std::string(dir) + "/" + name);
    if (in) {
      std::ostringstream s;
      s << in.rdbuf();
      return s.str();
    }
  }
  const auto& m = embeddedShaders();
  auto it = m.find(name);
  if (it == m.end()) throw std::runtime_error("shader " + name + " is missing from the build");
  return it->second;
}

GLuint program(const std::string& vs, const std::string& fs, const std::string& fsDefines) {
  GLuint p = glCreateProgram();
  GLuint a = compile(GL_VERTEX_SHADER, vs), b = compile(GL_FRAGMENT_SHADER, fs, fsDefines);
  glAttachShader(p, a);
  glAttachShader(p, b);
  glLinkProgram(p);
  glDeleteShader(a);
  glDeleteShader(b);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetProgramInfoLog(p, sizeof log, nullptr, log);
    throw std::runtime_error("shaders " + vs + " + " + fs + " do not link: " + log);
  }
  return p;
}

void makeTexture(GLuint& tex, GLenum internal, GLenum format, GLenum type, int w, int h, GLint filter) {
  if (!tex) glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexImage2D(GL_TEXTURE_2D, 0, GLint(internal), w, h, 0, format, type, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

GLuint target(GLenum internal, GLenum format, GLenum type, int w, int h, GLuint& tex) {
  makeTexture(tex, internal, format, type, w, h, GL_NEAREST);
  GLuint fbo = 0;
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("the renderer's own framebuffer is incomplete");
  return fbo;
}

void throwOnError(const char* what) {
  const GLenum err = glGetError();
  if (err == GL_NO_ERROR) return;
  std::ostringstream msg;
  msg << "OpenGL error 0x" << std::hex << err << " " << what;
  throw std::runtime_error(msg.str());
}

}  // namespace gl
}  // namespace sph2d
