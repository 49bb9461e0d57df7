#include "sim/render/gl_context.hpp"

#include <dlfcn.h>

#include <GL/osmesa.h>

#include <cstring>

#include "core/error.hpp"

namespace omniloc::sim {

GlContext::~GlContext() = default;

void GlContext::load(void* (*proc)(const char*)) {
  std::string missing;
#define OMNILOC_GL_LOAD(ret, name, args)                                         \
  gl_.name = reinterpret_cast<ret(*) args>(proc("gl" #name));                    \
  if (!gl_.name) missing += std::string(missing.empty() ? "" : ", ") + "gl" #name;
  OMNILOC_GL_FUNCS(OMNILOC_GL_LOAD)
#undef OMNILOC_GL_LOAD
  if (!missing.empty()) throw RuntimeFailure("GL back-end \"" + backend_ + "\": missing entry points " + missing);
  auto str = [&](GLenum name) {
    const auto* v = reinterpret_cast<const char*>(gl_.GetString(name));
    return std::string(v ? v : "");
  };
  device_.backend = backend_;
  device_.vendor = str(GL_VENDOR);
  device_.renderer = str(GL_RENDERER);
  device_.version = str(GL_VERSION);
}

bool GlContext::has_extension(const std::string& name) const {
  const char* ext = reinterpret_cast<const char*>(gl_.GetString(GL_EXTENSIONS));
  return ext && std::strstr(ext, name.c_str()) != nullptr;
}

unsigned GlContext::fragment_program(const char* source, const std::string& what) const {
  auto fail = [&](const std::string& stage, const std::string& log) {
    throw RuntimeFailure("GL back-end \"" + backend_ + "\": " + what + " shader " + stage + " failed: " + log);
  };
  const GLuint sh = gl_.CreateShader(GL_FRAGMENT_SHADER);
  if (!sh) fail("creation", "glCreateShader returned 0");
  gl_.ShaderSource(sh, 1, &source, nullptr);
  gl_.CompileShader(sh);
  GLint ok = GL_FALSE;
  char log[2048] = {};
  gl_.GetShaderiv(sh, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    gl_.GetShaderInfoLog(sh, sizeof log, nullptr, log);
    gl_.DeleteShader(sh);
    fail("compilation", log);
  }
  const GLuint prog = gl_.CreateProgram();
  gl_.AttachShader(prog, sh);
  gl_.LinkProgram(prog);
  gl_.DeleteShader(sh);  // stays alive while attached
  gl_.GetProgramiv(prog, GL_LINK_STATUS, &ok);
  if (!ok) {
    gl_.GetProgramInfoLog(prog, sizeof log, nullptr, log);
    gl_.DeleteProgram(prog);
    fail("linking", log);
  }
  return prog;
}

void GlContext::release_framebuffer() {
  if (fbo_) gl_.DeleteFramebuffers(1, &fbo_);
  if (color_) gl_.DeleteRenderbuffers(1, &color_);
  if (depth_) gl_.DeleteRenderbuffers(1, &depth_);
  fbo_ = color_ = depth_ = 0;
}

void GlContext::bind_framebuffer(int width, int height) {
  if (fbo_ && width == fb_w_ && height == fb_h_) {
    gl_.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
    return;
  }
  release_framebuffer();
  gl_.GenFramebuffers(1, &fbo_);
  gl_.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
  gl_.GenRenderbuffers(1, &color_);
  gl_.BindRenderbuffer(GL_RENDERBUFFER, color_);
  // 16 bits per channel: with 8, one GL level of a lamp-lit carpet was up to 8 DN of the output
  // once exposure control had raised exposure and gain in the dimmed hall (visible steps of 33, 41,
  // 50, 58 DN across the floor); the photometry now reads 10 of the 16 bits (docs/camera.md).
  gl_.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA16, width, height);
  gl_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_);
  gl_.GenRenderbuffers(1, &depth_);
  gl_.BindRenderbuffer(GL_RENDERBUFFER, depth_);
  gl_.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
  gl_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
  const GLenum st = gl_.CheckFramebufferStatus(GL_FRAMEBUFFER);
  if (st != GL_FRAMEBUFFER_COMPLETE)
    throw RuntimeFailure("GL back-end \"" + backend_ + "\": framebuffer " + std::to_string(width) + "x" + std::to_string(height) +
                         " incomplete (status 0x" + std::to_string(st) + ")");
  fb_w_ = width;
  fb_h_ = height;
}

void GlContext::read_rgba(std::vector<unsigned char>& out) const {
  out.resize(static_cast<std::size_t>(fb_w_) * fb_h_ * 4);
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl_.ReadPixels(0, 0, fb_w_, fb_h_, GL_RGBA, GL_UNSIGNED_BYTE, out.data());
  const GLenum err = gl_.GetError();
  if (err != GL_NO_ERROR) throw RuntimeFailure("GL back-end \"" + backend_ + "\": glReadPixels failed (error 0x" + std::to_string(err) + ")");
}

void GlContext::read_rgba16(std::vector<std::uint16_t>& out) const {
  out.resize(static_cast<std::size_t>(fb_w_) * fb_h_ * 4);
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 2);
  gl_.ReadPixels(0, 0, fb_w_, fb_h_, GL_RGBA, GL_UNSIGNED_SHORT, out.data());
  const GLenum err = gl_.GetError();
  if (err != GL_NO_ERROR) throw RuntimeFailure("GL back-end \"" + backend_ + "\": glReadPixels failed (error 0x" + std::to_string(err) + ")");
}

void GlContext::read_depth(std::vector<float>& out) const {
  out.resize(static_cast<std::size_t>(fb_w_) * fb_h_);
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 4);
  gl_.ReadPixels(0, 0, fb_w_, fb_h_, GL_DEPTH_COMPONENT, GL_FLOAT, out.data());
  const GLenum err = gl_.GetError();
  if (err != GL_NO_ERROR) throw RuntimeFailure("GL back-end \"" + backend_ + "\": glReadPixels (depth) failed (error 0x" + std::to_string(err) + ")");
}

namespace {

void* open_library(const std::string& backend, const char* lib) {
  void* h = ::dlopen(lib, RTLD_NOW | RTLD_LOCAL);
  if (!h) throw RuntimeFailure("GL back-end \"" + backend + "\": cannot load " + lib + " (" + ::dlerror() + ")");
  return h;
}

// The resolver handed to GlContext::load needs a plain function; each back-end sets its own.
thread_local void* (*t_osmesa_gpa)(const char*) = nullptr;
void* osmesa_proc(const char* n) { return t_osmesa_gpa(n); }

class OsmesaContext : public GlContext {
 public:
  OsmesaContext() {
    backend_ = "osmesa";
    device_.platform = "osmesa";
    lib_ = open_library(backend_, "libOSMesa.so.8");
    create_ = reinterpret_cast<OSMesaContext (*)(const int*, OSMesaContext)>(::dlsym(lib_, "OSMesaCreateContextAttribs"));
    make_ = reinterpret_cast<GLboolean (*)(OSMesaContext, void*, GLenum, GLsizei, GLsizei)>(::dlsym(lib_, "OSMesaMakeCurrent"));
    destroy_ = reinterpret_cast<void (*)(OSMesaContext)>(::dlsym(lib_, "OSMesaDestroyContext"));
    t_osmesa_gpa = reinterpret_cast<void* (*)(const char*)>(::dlsym(lib_, "OSMesaGetProcAddress"));
    if (!create_ || !make_ || !destroy_ || !t_osmesa_gpa) throw RuntimeFailure("GL back-end \"osmesa\": libOSMesa lacks the OSMesa 11.2 API");
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_PROFILE, OSMESA_COMPAT_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 0, 0};
    ctx_ = create_(attribs, nullptr);
    if (!ctx_) throw RuntimeFailure("GL back-end \"osmesa\": OSMesaCreateContextAttribs failed (no GL 3.0 compatibility context)");
    make_current();
    load(osmesa_proc);
  }
  ~OsmesaContext() override {
    release_framebuffer();
    if (ctx_) destroy_(ctx_);
  }
  void make_current() override {
    // OSMesa needs a client buffer even though we render into an FBO.
    if (!make_(ctx_, dummy_, GL_UNSIGNED_BYTE, 1, 1)) throw RuntimeFailure("GL back-end \"osmesa\": OSMesaMakeCurrent failed");
  }

 private:
  void* lib_ = nullptr;
  OSMesaContext ctx_ = nullptr;
  unsigned char dummy_[16] = {};
  OSMesaContext (*create_)(const int*, OSMesaContext) = nullptr;
  GLboolean (*make_)(OSMesaContext, void*, GLenum, GLsizei, GLsizei) = nullptr;
  void (*destroy_)(OSMesaContext) = nullptr;
};

}  // namespace

std::vector<std::string> gl_backends() { return {"osmesa", "egl"}; }

std::unique_ptr<GlContext> make_gl_context(const std::string& backend) {
  if (backend == "osmesa") return std::make_unique<OsmesaContext>();
  if (backend == "egl") return make_egl_context();
  throw RuntimeFailure("unknown GL back-end \"" + backend + "\" (known: osmesa, egl)");
}

}  // namespace omniloc::sim
