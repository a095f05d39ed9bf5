// gl_api.hpp — the OpenGL functions sph2d::render calls, taken from a table chosen per context
// instead of bound at link time.
//
// Design: a program that links libglvnd's libOpenGL (a GL game usually does) binds every gl*
// symbol to glvnd's dispatch, which reaches only contexts made current through EGL or GLX. An
// OSMesa context is neither: made current by OSMesaMakeCurrent on a thread where no EGL or GLX
// context ever was, link-time gl* calls in it go nowhere (glGetString gives null, draws are
// dropped). So the renderer calls no gl* symbol directly: every function it uses is a member of
// an Api table, and each gl* name is a macro (below) for that member of the calling thread's
// table. There are two tables:
//  - osmesaApi(): Mesa's own entry points from OSMesaGetProcAddress, which dispatch to Mesa's
//    current context (OSMesa's, or a Mesa EGL/GLX one) whatever the program links. A Renderer
//    in its own OSMesa context uses it, so that path works in any link order.
//  - linkedApi(): the gl* symbols the program links (libOSMesa's, or libOpenGL's when that comes
//    first), the functions the game itself calls. A Renderer in the caller's context uses it,
//    unless those reach no context while an OSMesa one is current (a game with its own OSMesa
//    context that also links libOpenGL): then osmesaApi() (renderer.cpp).
// The calling thread's table is linkedApi() unless a UseApi scope says otherwise; the Renderer
// opens one at the top of every call (GL contexts are current per thread; so are tables).
// A new GL function for a pass goes into SPH2D_GL_FUNCTIONS and gets its macro below; CTest
// (glvnd/no_link_time_gl) fails when an object of sph2d::render other than gl_api.cpp's
// references a gl* symbol.
#pragma once

#define GL_GLEXT_PROTOTYPES 1  // the declarations give each function's type (decltype below)
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>

/// Every OpenGL function sph2d::render calls, without the gl prefix.
#define SPH2D_GL_FUNCTIONS(X) \
  X(ActiveTexture)            \
  X(AttachShader)             \
  X(BindBuffer)               \
  X(BindFramebuffer)          \
  X(BindSampler)              \
  X(BindTexture)              \
  X(BindVertexArray)          \
  X(BlendEquation)            \
  X(BlendEquationSeparate)    \
  X(BlendEquationSeparatei)   \
  X(BlendFunc)                \
  X(BlendFuncSeparate)        \
  X(BlendFuncSeparatei)       \
  X(BlitFramebuffer)          \
  X(BufferData)               \
  X(CheckFramebufferStatus)   \
  X(ClampColor)               \
  X(Clear)                    \
  X(ClearColor)               \
  X(ColorMask)                \
  X(ColorMaski)               \
  X(CompileShader)            \
  X(CopyImageSubData)         \
  X(CreateProgram)            \
  X(CreateShader)             \
  X(DeleteBuffers)            \
  X(DeleteFramebuffers)       \
  X(DeleteProgram)            \
  X(DeleteShader)             \
  X(DeleteTextures)           \
  X(DeleteVertexArrays)       \
  X(Disable)                  \
  X(Disablei)                 \
  X(DrawArrays)               \
  X(DrawArraysInstanced)      \
  X(Enable)                   \
  X(EnableVertexAttribArray)  \
  X(Enablei)                  \
  X(Finish)                   \
  X(FramebufferTexture2D)     \
  X(GenBuffers)               \
  X(GenFramebuffers)          \
  X(GenTextures)              \
  X(GenVertexArrays)          \
  X(GetBooleani_v)            \
  X(GetError)                 \
  X(GetFloatv)                \
  X(GetIntegeri_v)            \
  X(GetIntegerv)              \
  X(GetProgramInfoLog)        \
  X(GetProgramiv)             \
  X(GetShaderInfoLog)         \
  X(GetShaderiv)              \
  X(GetString)                \
  X(GetStringi)               \
  X(GetUniformLocation)       \
  X(IsEnabled)                \
  X(IsEnabledi)               \
  X(IsFramebuffer)            \
  X(LinkProgram)              \
  X(PixelStorei)              \
  X(PixelTransferf)           \
  X(PixelTransferi)           \
  X(PointParameteri)          \
  X(PolygonMode)              \
  X(ReadPixels)               \
  X(Scissor)                  \
  X(ShaderSource)             \
  X(TexImage2D)               \
  X(TexParameteri)            \
  X(TexSubImage2D)            \
  X(Uniform1f)                \
  X(Uniform1i)                \
  X(Uniform2f)                \
  X(Uniform2fv)               \
  X(Uniform3f)                \
  X(Uniform3fv)               \
  X(Uniform4f)                \
  X(Uniform3i)                \
  X(Uniform4i)                \
  X(UseProgram)               \
  X(VertexAttribDivisor)      \
  X(VertexAttribPointer)      \
  X(Viewport)

namespace sph2d::gl {

/// One pointer per function of SPH2D_GL_FUNCTIONS, named without the gl prefix.
struct Api {
#define SPH2D_GL_MEMBER(name) decltype(&::gl##name) name;
  SPH2D_GL_FUNCTIONS(SPH2D_GL_MEMBER)
#undef SPH2D_GL_MEMBER
  const char* source;  ///< where the pointers come from: "linked" or "OSMesaGetProcAddress"
};

/// The gl* symbols the program links (libOSMesa's, or libglvnd's libOpenGL's when it comes first).
const Api& linkedApi();
/// Mesa's entry points, from OSMesaGetProcAddress (resolved once). They reach Mesa's current
/// context whatever the link order. Throws std::runtime_error naming a function OSMesa lacks.
const Api& osmesaApi();

namespace detail {
extern thread_local const Api* current;  ///< the calling thread's table; never null
}  // namespace detail

/// The calling thread's table (linkedApi() unless a UseApi is open).
inline const Api& api() { return *detail::current; }

/// Makes `a` the calling thread's table until the end of the scope, then the one before.
class UseApi {
 public:
  explicit UseApi(const Api& a) : before_(detail::current) { detail::current = &a; }
  ~UseApi() { detail::current = before_; }
  UseApi(const UseApi&) = delete;
  UseApi& operator=(const UseApi&) = delete;

 private:
  const Api* before_;
};

}  // namespace sph2d::gl

#ifndef SPH2D_GL_API_NO_MACROS  // gl_api.cpp takes the linked symbols' addresses
#define SPH2D_GL(name) (::sph2d::gl::detail::current->name)
#define glActiveTexture SPH2D_GL(ActiveTexture)
#define glAttachShader SPH2D_GL(AttachShader)
#define glBindBuffer SPH2D_GL(BindBuffer)
#define glBindFramebuffer SPH2D_GL(BindFramebuffer)
#define glBindSampler SPH2D_GL(BindSampler)
#define glBindTexture SPH2D_GL(BindTexture)
#define glBindVertexArray SPH2D_GL(BindVertexArray)
#define glBlendEquation SPH2D_GL(BlendEquation)
#define glBlendEquationSeparate SPH2D_GL(BlendEquationSeparate)
#define glBlendEquationSeparatei SPH2D_GL(BlendEquationSeparatei)
#define glBlendFunc SPH2D_GL(BlendFunc)
#define glBlendFuncSeparate SPH2D_GL(BlendFuncSeparate)
#define glBlendFuncSeparatei SPH2D_GL(BlendFuncSeparatei)
#define glBlitFramebuffer SPH2D_GL(BlitFramebuffer)
#define glBufferData SPH2D_GL(BufferData)
#define glCheckFramebufferStatus SPH2D_GL(CheckFramebufferStatus)
#define glClampColor SPH2D_GL(ClampColor)
#define glClear SPH2D_GL(Clear)
#define glClearColor SPH2D_GL(ClearColor)
#define glColorMask SPH2D_GL(ColorMask)
#define glColorMaski SPH2D_GL(ColorMaski)
#define glCompileShader SPH2D_GL(CompileShader)
#define glCopyImageSubData SPH2D_GL(CopyImageSubData)
#define glCreateProgram SPH2D_GL(CreateProgram)
#define glCreateShader SPH2D_GL(CreateShader)
#define glDeleteBuffers SPH2D_GL(DeleteBuffers)
#define glDeleteFramebuffers SPH2D_GL(DeleteFramebuffers)
#define glDeleteProgram SPH2D_GL(DeleteProgram)
#define glDeleteShader SPH2D_GL(DeleteShader)
#define glDeleteTextures SPH2D_GL(DeleteTextures)
#define glDeleteVertexArrays SPH2D_GL(DeleteVertexArrays)
#define glDisable SPH2D_GL(Disable)
#define glDisablei SPH2D_GL(Disablei)
#define glDrawArrays SPH2D_GL(DrawArrays)
#define glDrawArraysInstanced SPH2D_GL(DrawArraysInstanced)
#define glEnable SPH2D_GL(Enable)
#define glEnableVertexAttribArray SPH2D_GL(EnableVertexAttribArray)
#define glEnablei SPH2D_GL(Enablei)
#define glFinish SPH2D_GL(Finish)
#define glFramebufferTexture2D SPH2D_GL(FramebufferTexture2D)
#define glGenBuffers SPH2D_GL(GenBuffers)
#define glGenFramebuffers SPH2D_GL(GenFramebuffers)
#define glGenTextures SPH2D_GL(GenTextures)
#define glGenVertexArrays SPH2D_GL(GenVertexArrays)
#define glGetBooleani_v SPH2D_GL(GetBooleani_v)
#define glGetError SPH2D_GL(GetError)
#define glGetFloatv SPH2D_GL(GetFloatv)
#define glGetIntegeri_v SPH2D_GL(GetIntegeri_v)
#define glGetIntegerv SPH2D_GL(GetIntegerv)
#define glGetProgramInfoLog SPH2D_GL(GetProgramInfoLog)
#define glGetProgramiv SPH2D_GL(GetProgramiv)
#define glGetShaderInfoLog SPH2D_GL(GetShaderInfoLog)
#define glGetShaderiv SPH2D_GL(GetShaderiv)
#define glGetString SPH2D_GL(GetString)
#define glGetStringi SPH2D_GL(GetStringi)
#define glGetUniformLocation SPH2D_GL(GetUniformLocation)
#define glIsEnabled SPH2D_GL(IsEnabled)
#define glIsEnabledi SPH2D_GL(IsEnabledi)
#define glIsFramebuffer SPH2D_GL(IsFramebuffer)
#define glLinkProgram SPH2D_GL(LinkProgram)
#define glPixelStorei SPH2D_GL(PixelStorei)
#define glPixelTransferf SPH2D_GL(PixelTransferf)
#define glPixelTransferi SPH2D_GL(PixelTransferi)
#define glPointParameteri SPH2D_GL(PointParameteri)
#define glPolygonMode SPH2D_GL(PolygonMode)
#define glReadPixels SPH2D_GL(ReadPixels)
#define glScissor SPH2D_GL(Scissor)
#define glShaderSource SPH2D_GL(ShaderSource)
#define glTexImage2D SPH2D_GL(TexImage2D)
#define glTexParameteri SPH2D_GL(TexParameteri)
#define glTexSubImage2D SPH2D_GL(TexSubImage2D)
#define glUniform1f SPH2D_GL(Uniform1f)
#define glUniform1i SPH2D_GL(Uniform1i)
#define glUniform2f SPH2D_GL(Uniform2f)
#define glUniform2fv SPH2D_GL(Uniform2fv)
#define glUniform3f SPH2D_GL(Uniform3f)
#define glUniform3fv SPH2D_GL(Uniform3fv)
#define glUniform4f SPH2D_GL(Uniform4f)
#define glUniform3i SPH2D_GL(Uniform3i)
#define glUniform4i SPH2D_GL(Uniform4i)
#define glUseProgram SPH2D_GL(UseProgram)
#define glVertexAttribDivisor SPH2D_GL(VertexAttribDivisor)
#define glVertexAttribPointer SPH2D_GL(VertexAttribPointer)
#define glViewport SPH2D_GL(Viewport)
#endif
