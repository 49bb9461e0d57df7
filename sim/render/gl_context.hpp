#pragma once
// Off-screen GL behind a small interface with two back-ends chosen at run time: "osmesa" (Mesa's
// OSMesa, llvmpipe) and "egl" (an EGL device: a GPU, Mesa's software device or Mesa's surfaceless
// display; egl_device.hpp says which is chosen). Both libraries are loaded with dlopen
// and every GL entry point is resolved through the back-end's own GetProcAddress into GlApi, so
// neither glvnd's libGL nor libOSMesa is linked and their gl* symbols can never clash. Rendering
// always goes into a framebuffer object that is read back with glReadPixels, the same on both.
#include <memory>
#include <cstdint>
#include <string>
#include <vector>

#include <GL/gl.h>
#include <GL/glext.h>

#include "sim/render/gl_device_info.hpp"

namespace omniloc::sim {

/// The GL entry points the renderer uses (compatibility profile: fixed function + FBOs).
struct GlApi {
#define OMNILOC_GL_FUNCS(X)                                                                       \
  X(void, Viewport, (GLint, GLint, GLsizei, GLsizei))                                             \
  X(void, ClearColor, (GLfloat, GLfloat, GLfloat, GLfloat))                                       \
  X(void, Clear, (GLbitfield))                                                                    \
  X(void, Enable, (GLenum))                                                                       \
  X(void, Disable, (GLenum))                                                                      \
  X(void, DepthFunc, (GLenum))                                                                    \
  X(void, DepthMask, (GLboolean))                                                                 \
  X(void, MatrixMode, (GLenum))                                                                   \
  X(void, LoadIdentity, ())                                                                       \
  X(void, Ortho, (GLdouble, GLdouble, GLdouble, GLdouble, GLdouble, GLdouble))                    \
  X(void, ShadeModel, (GLenum))                                                                   \
  X(void, GenTextures, (GLsizei, GLuint*))                                                        \
  X(void, DeleteTextures, (GLsizei, const GLuint*))                                               \
  X(void, BindTexture, (GLenum, GLuint))                                                          \
  X(void, ActiveTexture, (GLenum))                                                                \
  X(void, TexImage2D, (GLenum, GLint, GLint, GLsizei, GLsizei, GLint, GLenum, GLenum, const void*)) \
  X(void, TexParameteri, (GLenum, GLenum, GLint))                                                 \
  X(void, TexParameterf, (GLenum, GLenum, GLfloat))                                               \
  X(void, TexParameterfv, (GLenum, GLenum, const GLfloat*))                                       \
  X(void, TexEnvi, (GLenum, GLenum, GLint))                                                       \
  X(void, EnableClientState, (GLenum))                                                            \
  X(void, DisableClientState, (GLenum))                                                           \
  X(void, VertexPointer, (GLint, GLenum, GLsizei, const void*))                                   \
  X(void, ColorPointer, (GLint, GLenum, GLsizei, const void*))                                    \
  X(void, TexCoordPointer, (GLint, GLenum, GLsizei, const void*))                                 \
  X(void, DrawArrays, (GLenum, GLint, GLsizei))                                                   \
  X(void, DrawElements, (GLenum, GLsizei, GLenum, const void*))                                   \
  X(void, ReadPixels, (GLint, GLint, GLsizei, GLsizei, GLenum, GLenum, void*))                    \
  X(void, PixelStorei, (GLenum, GLint))                                                           \
  X(void, Finish, ())                                                                             \
  X(GLenum, GetError, ())                                                                         \
  X(const GLubyte*, GetString, (GLenum))                                                          \
  X(void, GenFramebuffers, (GLsizei, GLuint*))                                                    \
  X(void, DeleteFramebuffers, (GLsizei, const GLuint*))                                           \
  X(void, BindFramebuffer, (GLenum, GLuint))                                                      \
  X(void, FramebufferRenderbuffer, (GLenum, GLenum, GLenum, GLuint))                              \
  X(GLenum, CheckFramebufferStatus, (GLenum))                                                     \
  X(void, GenRenderbuffers, (GLsizei, GLuint*))                                                   \
  X(void, DeleteRenderbuffers, (GLsizei, const GLuint*))                                          \
  X(void, BindRenderbuffer, (GLenum, GLuint))                                                     \
  X(void, RenderbufferStorage, (GLenum, GLenum, GLsizei, GLsizei))                               \
  X(GLuint, CreateShader, (GLenum))                                                               \
  X(void, DeleteShader, (GLuint))                                                                 \
  X(void, ShaderSource, (GLuint, GLsizei, const GLchar* const*, const GLint*))                    \
  X(void, CompileShader, (GLuint))                                                                \
  X(void, GetShaderiv, (GLuint, GLenum, GLint*))                                                  \
  X(void, GetShaderInfoLog, (GLuint, GLsizei, GLsizei*, GLchar*))                                 \
  X(GLuint, CreateProgram, ())                                                                    \
  X(void, DeleteProgram, (GLuint))                                                                \
  X(void, AttachShader, (GLuint, GLuint))                                                         \
  X(void, LinkProgram, (GLuint))                                                                  \
  X(void, GetProgramiv, (GLuint, GLenum, GLint*))                                                 \
  X(void, GetProgramInfoLog, (GLuint, GLsizei, GLsizei*, GLchar*))                                \
  X(void, UseProgram, (GLuint))                                                                   \
  X(GLint, GetUniformLocation, (GLuint, const GLchar*))                                           \
  X(void, Uniform1i, (GLint, GLint))                                                              \
  X(void, Uniform1f, (GLint, GLfloat))                                                            \
  X(void, Uniform2f, (GLint, GLfloat, GLfloat))                                                   \
  X(void, Uniform3f, (GLint, GLfloat, GLfloat, GLfloat))                                          \
  X(void, Uniform4f, (GLint, GLfloat, GLfloat, GLfloat, GLfloat))
#define OMNILOC_GL_MEMBER(ret, name, args) ret(*name) args = nullptr;
  OMNILOC_GL_FUNCS(OMNILOC_GL_MEMBER)
#undef OMNILOC_GL_MEMBER
};

/// A current GL context with an RGBA8 + depth framebuffer object of a given size.
class GlContext {
 public:
  virtual ~GlContext();
  const GlApi& gl() const { return gl_; }
  const std::string& backend() const { return backend_; }
  /// The device the context renders on (GL strings filled once the context is current).
  const GlDeviceInfo& device() const { return device_; }
  /// Makes the context current on this thread (contexts are per camera, cameras per run).
  virtual void make_current() = 0;
  /// (Re)creates the framebuffer object for rendering at width x height and binds it.
  void bind_framebuffer(int width, int height);
  /// Reads the bound framebuffer as RGBA8, rows bottom-up (GL order).
  void read_rgba(std::vector<unsigned char>& out) const;
  /// The same at the framebuffer's 16 bits per channel.
  void read_rgba16(std::vector<std::uint16_t>& out) const;
  /// The depth buffer as floats in [0, 1] (GL order; 1 where nothing that writes depth was drawn).
  void read_depth(std::vector<float>& out) const;
  bool has_extension(const std::string& name) const;
  /// Compiles and links a program of one GLSL fragment shader (the vertex stage stays fixed
  /// function). Throws RuntimeFailure with the compiler's log, naming the back-end and `what`.
  unsigned fragment_program(const char* source, const std::string& what) const;

 protected:
  /// Resolves the entry points and reads the GL vendor, renderer and version into device_.
  void load(void* (*proc)(const char*));
  void release_framebuffer();
  GlApi gl_;
  std::string backend_;
  GlDeviceInfo device_;
  unsigned fbo_ = 0, color_ = 0, depth_ = 0;
  int fb_w_ = 0, fb_h_ = 0;
};

/// "osmesa" or "egl". Throws omniloc::RuntimeFailure naming the back-end and why it failed
/// (for "egl": every device tried and what each answered).
std::unique_ptr<GlContext> make_gl_context(const std::string& backend);
/// The "egl" back-end on the device egl_device.hpp's rules choose (egl_device.cpp).
std::unique_ptr<GlContext> make_egl_context();
std::vector<std::string> gl_backends();

}  // namespace omniloc::sim
