// The "egl" back-end: device enumeration, the choice of a device (egl_device.hpp) and the context.
#include "sim/render/egl_device.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>

#include "core/error.hpp"
#include "sim/render/gl_context.hpp"

namespace omniloc::sim {

EglDeviceRequest parse_egl_device_request(const char* value) {
  EglDeviceRequest r;
  if (!value) return r;
  r.text = value;
  if (r.text.empty() || r.text == "auto") return r;
  if (r.text == "surfaceless") {
    r.kind = EglDeviceRequest::kSurfaceless;
    return r;
  }
  const bool digits = r.text.size() <= 4 && std::all_of(r.text.begin(), r.text.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (!digits)
    throw ConfigError("$OMNILOC_EGL_DEVICE", "\"" + r.text + "\"",
                      "\"auto\", \"surfaceless\" or an EGL device index (a number; omniloc gl-devices lists them)");
  r.kind = EglDeviceRequest::kIndex;
  r.index = std::stoi(r.text);
  return r;
}

std::vector<int> egl_auto_order(const std::vector<EglDeviceDesc>& devices, long rotation) {
  std::vector<int> cuda, other_hw, software;
  for (int i = 0; i < static_cast<int>(devices.size()); ++i) {
    const EglDeviceDesc& d = devices[static_cast<std::size_t>(i)];
    (d.software ? software : d.cuda_device >= 0 ? cuda : other_hw).push_back(i);
  }
  std::stable_sort(cuda.begin(), cuda.end(), [&](int a, int b) {
    return devices[static_cast<std::size_t>(a)].cuda_device < devices[static_cast<std::size_t>(b)].cuda_device;
  });
  // The GPUs a process starts at rotate with the rotation: the CUDA devices when there are any
  // (the ones the scheduler gave), else the other hardware devices.
  std::vector<int>& gpus = cuda.empty() ? other_hw : cuda;
  if (gpus.size() > 1) {
    const long n = static_cast<long>(gpus.size());
    std::rotate(gpus.begin(), gpus.begin() + ((rotation % n) + n) % n, gpus.end());
  }
  std::vector<int> order = cuda;
  order.insert(order.end(), other_hw.begin(), other_hw.end());
  order.insert(order.end(), software.begin(), software.end());
  order.push_back(-1);
  return order;
}

std::string effective_gl_backend(const std::string& configured) {
  const char* env = std::getenv("OMNILOC_GL_BACKEND");
  if (!env || !*env) return configured;
  const std::string v = env;
  const auto known = gl_backends();
  if (std::find(known.begin(), known.end(), v) == known.end())
    throw ConfigError("$OMNILOC_GL_BACKEND", "\"" + v + "\"", "one of \"osmesa\", \"egl\" (it overrides every scenario's camera.backend)");
  return v;
}

namespace {

// libEGL and the entry points the back-end needs, loaded once per process (never unloaded: the
// drivers it pulls in keep threads and atexit handlers).
struct EglLib {
  void* lib = nullptr;
  void* (*gpa)(const char*) = nullptr;
  EGLBoolean (*initialize)(EGLDisplay, EGLint*, EGLint*) = nullptr;
  EGLBoolean (*bind_api)(EGLenum) = nullptr;
  EGLBoolean (*choose)(EGLDisplay, const EGLint*, EGLConfig*, EGLint, EGLint*) = nullptr;
  EGLContext (*create)(EGLDisplay, EGLConfig, EGLContext, const EGLint*) = nullptr;
  EGLBoolean (*make)(EGLDisplay, EGLSurface, EGLSurface, EGLContext) = nullptr;
  EGLBoolean (*destroy)(EGLDisplay, EGLContext) = nullptr;
  EGLint (*get_error)() = nullptr;
  const char* (*query)(EGLDisplay, EGLint) = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC get_display = nullptr;
  PFNEGLQUERYDEVICESEXTPROC query_devices = nullptr;         // EGL_EXT_device_enumeration
  PFNEGLQUERYDEVICESTRINGEXTPROC device_string = nullptr;    // EGL_EXT_device_query
  PFNEGLQUERYDEVICEATTRIBEXTPROC device_attrib = nullptr;

  static const EglLib& get() {
    static std::mutex m;
    static std::unique_ptr<EglLib> lib;
    std::lock_guard<std::mutex> lock(m);
    if (!lib) lib = std::make_unique<EglLib>(load());
    return *lib;
  }

 private:
  static EglLib load() {
    EglLib e;
    e.lib = ::dlopen("libEGL.so.1", RTLD_NOW | RTLD_LOCAL);
    if (!e.lib) throw RuntimeFailure(std::string("GL back-end \"egl\": cannot load libEGL.so.1 (") + ::dlerror() + ")");
    auto sym = [&](const char* n) {
      void* p = ::dlsym(e.lib, n);
      if (!p) throw RuntimeFailure(std::string("GL back-end \"egl\": libEGL lacks ") + n);
      return p;
    };
    e.gpa = reinterpret_cast<void* (*)(const char*)>(sym("eglGetProcAddress"));
    e.initialize = reinterpret_cast<decltype(e.initialize)>(sym("eglInitialize"));
    e.bind_api = reinterpret_cast<decltype(e.bind_api)>(sym("eglBindAPI"));
    e.choose = reinterpret_cast<decltype(e.choose)>(sym("eglChooseConfig"));
    e.create = reinterpret_cast<decltype(e.create)>(sym("eglCreateContext"));
    e.make = reinterpret_cast<decltype(e.make)>(sym("eglMakeCurrent"));
    e.destroy = reinterpret_cast<decltype(e.destroy)>(sym("eglDestroyContext"));
    e.get_error = reinterpret_cast<decltype(e.get_error)>(sym("eglGetError"));
    e.query = reinterpret_cast<decltype(e.query)>(sym("eglQueryString"));
    e.get_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(e.gpa("eglGetPlatformDisplayEXT"));
    if (!e.get_display) throw RuntimeFailure("GL back-end \"egl\": no eglGetPlatformDisplayEXT (EGL_EXT_platform_base)");
    e.query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(e.gpa("eglQueryDevicesEXT"));
    e.device_string = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(e.gpa("eglQueryDeviceStringEXT"));
    e.device_attrib = reinterpret_cast<PFNEGLQUERYDEVICEATTRIBEXTPROC>(e.gpa("eglQueryDeviceAttribEXT"));
    return e;
  }
};

std::string hex(EGLint v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%04x", static_cast<unsigned>(v));
  return b;
}

std::vector<EGLDeviceEXT> device_handles(const EglLib& e) {
  if (!e.query_devices) return {};
  EGLint n = 0;
  if (!e.query_devices(0, nullptr, &n) || n <= 0) return {};
  std::vector<EGLDeviceEXT> h(static_cast<std::size_t>(n));
  if (!e.query_devices(n, h.data(), &n)) return {};
  h.resize(static_cast<std::size_t>(std::max(0, n)));
  return h;
}

EglDeviceDesc describe(const EglLib& e, EGLDeviceEXT dev, int index) {
  EglDeviceDesc d;
  d.index = index;
  const char* ext = e.device_string ? e.device_string(dev, EGL_EXTENSIONS) : nullptr;
  d.extensions = ext ? ext : "";
  auto has = [&](const char* name) {
    // Whole words only: one extension's name can be the start of another's.
    const std::string w = " " + d.extensions + " ";
    return w.find(" " + std::string(name) + " ") != std::string::npos;
  };
  d.software = has("EGL_MESA_device_software");
  if (has("EGL_NV_device_cuda") && e.device_attrib) {
    EGLAttrib v = -1;
    if (e.device_attrib(dev, EGL_CUDA_DEVICE_NV, &v)) d.cuda_device = static_cast<int>(v);
  }
  if (has("EGL_EXT_device_drm") && e.device_string) {
    const char* node = has("EGL_EXT_device_drm_render_node") ? e.device_string(dev, EGL_DRM_RENDER_NODE_FILE_EXT) : nullptr;
    if (!node) node = e.device_string(dev, EGL_DRM_DEVICE_FILE_EXT);
    if (node) d.drm_node = node;
  }
  e.get_error();  // queries a driver does not answer leave an error behind; it is not ours
  return d;
}

thread_local void* (*t_egl_gpa)(const char*) = nullptr;
void* egl_proc(const char* n) { return t_egl_gpa(n); }

class EglContext : public GlContext {
 public:
  // Opens `dpy` (a device's display or the surfaceless one) and creates a compatibility context;
  // throws RuntimeFailure saying which step failed.
  EglContext(const EglLib& e, EGLDisplay dpy, GlDeviceInfo info) : e_(e), dpy_(dpy) {
    backend_ = "egl";
    device_ = std::move(info);
    EGLint major = 0, minor = 0;
    if (dpy_ == EGL_NO_DISPLAY) throw RuntimeFailure("no display (EGL error " + hex(e_.get_error()) + ")");
    if (!e_.initialize(dpy_, &major, &minor)) throw RuntimeFailure("eglInitialize failed (EGL error " + hex(e_.get_error()) + ")");
    if (!e_.bind_api(EGL_OPENGL_API)) throw RuntimeFailure("desktop OpenGL API not available");
    const char* exts = e_.query(dpy_, EGL_EXTENSIONS);
    const std::string x = exts ? exts : "";
    if (x.find("EGL_KHR_surfaceless_context") == std::string::npos) throw RuntimeFailure("no EGL_KHR_surfaceless_context");
    // A config-less context where the display allows it (EGL_KHR_no_config_context); else any
    // OpenGL config with pbuffers, the surface type that device displays have (no windows there).
    EGLConfig cfg = EGL_NO_CONFIG_KHR;
    if (x.find("EGL_KHR_no_config_context") == std::string::npos) {
      const EGLint attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_NONE};
      EGLint n = 0;
      if (!e_.choose(dpy_, attribs, &cfg, 1, &n) || n < 1) throw RuntimeFailure("no OpenGL config and no EGL_KHR_no_config_context");
    }
    const EGLint ctx_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                  EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT, EGL_NONE};
    ctx_ = e_.create(dpy_, cfg, EGL_NO_CONTEXT, ctx_attribs);
    if (ctx_ == EGL_NO_CONTEXT) throw RuntimeFailure("eglCreateContext (GL 3.0 compatibility) failed (EGL error " + hex(e_.get_error()) + ")");
    make_current();
    t_egl_gpa = e_.gpa;
    load(egl_proc);
  }
  ~EglContext() override {
    release_framebuffer();
    if (ctx_ != EGL_NO_CONTEXT) e_.destroy(dpy_, ctx_);
  }
  void make_current() override {
    if (!e_.make(dpy_, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx_)) throw RuntimeFailure("eglMakeCurrent (surfaceless) failed (EGL error " + hex(e_.get_error()) + ")");
  }

 private:
  const EglLib& e_;
  EGLDisplay dpy_ = EGL_NO_DISPLAY;
  EGLContext ctx_ = EGL_NO_CONTEXT;
};

}  // namespace

std::vector<EglDeviceDesc> egl_devices() {
  const EglLib& e = EglLib::get();
  if (!e.query_devices) throw RuntimeFailure("GL back-end \"egl\": libEGL has no EGL_EXT_device_enumeration");
  std::vector<EglDeviceDesc> out;
  const auto h = device_handles(e);
  for (std::size_t i = 0; i < h.size(); ++i) out.push_back(describe(e, h[i], static_cast<int>(i)));
  return out;
}

std::unique_ptr<GlContext> make_egl_context() {
  const EglDeviceRequest req = parse_egl_device_request(std::getenv("OMNILOC_EGL_DEVICE"));
  const EglLib& e = EglLib::get();
  const auto handles = device_handles(e);
  std::vector<EglDeviceDesc> devs;
  for (std::size_t i = 0; i < handles.size(); ++i) devs.push_back(describe(e, handles[i], static_cast<int>(i)));

  std::vector<int> order;
  std::string selection = "auto";
  if (req.kind == EglDeviceRequest::kIndex) {
    if (req.index >= static_cast<int>(devs.size()))
      throw RuntimeFailure("GL back-end \"egl\": OMNILOC_EGL_DEVICE=" + req.text + " but this machine lists " + std::to_string(devs.size()) +
                           " EGL device(s) (omniloc gl-devices)");
    order = {req.index};
    selection = "OMNILOC_EGL_DEVICE=" + req.text;
  } else if (req.kind == EglDeviceRequest::kSurfaceless) {
    order = {-1};
    selection = "OMNILOC_EGL_DEVICE=surfaceless";
  } else {
    order = egl_auto_order(devs, static_cast<long>(::getpid()));
  }
  // The first candidate that gives a context wins; what the others answered goes into the error.
  std::string tried;
  for (int i : order) {
    GlDeviceInfo info;
    info.backend = "egl";
    info.selection = selection;
    EGLDisplay dpy = EGL_NO_DISPLAY;
    std::string what;
    if (i < 0) {
      info.platform = "surfaceless";
      what = "surfaceless Mesa display";
      dpy = e.get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    } else {
      const EglDeviceDesc& d = devs[static_cast<std::size_t>(i)];
      info.platform = "device";
      info.egl_device = d.index;
      info.cuda_device = d.cuda_device;
      info.drm_node = d.drm_node;
      what = "EGL device " + std::to_string(d.index) + (d.software ? " (software)" : "") + (d.drm_node.empty() ? "" : " " + d.drm_node);
      dpy = e.get_display(EGL_PLATFORM_DEVICE_EXT, handles[static_cast<std::size_t>(i)], nullptr);
    }
    try {
      return std::make_unique<EglContext>(e, dpy, std::move(info));
    } catch (const RuntimeFailure& err) {
      tried += (tried.empty() ? "" : "; ") + what + ": " + err.what();
    }
  }
  throw RuntimeFailure("GL back-end \"egl\": no device could render (" + std::to_string(devs.size()) + " EGL device(s) listed; tried " + tried +
                       ")");
}

std::string gl_backend_problem(const std::string& backend) {
  static std::mutex m;
  static std::map<std::string, std::string> answers;
  const char* dev = std::getenv("OMNILOC_EGL_DEVICE");
  const std::string key = backend + "|" + (dev ? dev : "");
  if (backend == "egl") parse_egl_device_request(dev);  // a malformed value is the user's ConfigError, not a probe failure
  std::lock_guard<std::mutex> lock(m);
  const auto it = answers.find(key);
  if (it != answers.end()) return it->second;
  std::string problem;
  try {
    make_gl_context(backend);
  } catch (const RuntimeFailure& e) {
    problem = e.what();
  }
  return answers[key] = problem;
}

}  // namespace omniloc::sim
