// The "egl" back-end's device choice (docs/camera.md "GPUs"): the order "auto" tries devices in, OMNILOC_EGL_DEVICE
// and OMNILOC_GL_BACKEND, and, on this machine's real libEGL (Mesa's device platform and surfaceless
// display, no GPU), enumeration, selection, the fallback and the error path. The GPU side is
// measured by scripts/gpu_check.sh (docs/performance.md), not here: CI has no GPU.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/error.hpp"
#include "core/field.hpp"
#include "core/atomic_file.hpp"
#include "core/rng.hpp"
#include "sim/render/egl_device.hpp"
#include "sim/render/gl_context.hpp"
#include "sim/render/panoramic_camera.hpp"
#include "testing/scenes.hpp"
#include "core/install_paths.hpp"

namespace fs = std::filesystem;
using namespace omniloc;
using namespace omniloc::sim;

namespace {

EglDeviceDesc dev(int index, bool software, int cuda = -1) {
  EglDeviceDesc d;
  d.index = index;
  d.software = software;
  d.cuda_device = cuda;
  return d;
}

// Sets an environment variable for one scope (the previous value comes back).
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    if (value) ::setenv(name, value, 1);
    else ::unsetenv(name);
  }
  ~ScopedEnv() {
    if (had_) ::setenv(name_.c_str(), old_.c_str(), 1);
    else ::unsetenv(name_.c_str());
  }

 private:
  std::string name_, old_;
  bool had_ = false;
};

// The EGL back-end as this machine's libEGL gives it, or the reason it cannot.
std::string egl_here() {
  try {
    (void)make_gl_context("egl");
    return "";
  } catch (const std::exception& e) {
    return e.what();
  }
}

int shell(const std::string& cmd, std::string* err) {
  const fs::path log = fs::temp_directory_path() / ("omniloc_gl_device_" + std::to_string(::getpid()) + ".err");
  const int st = std::system((cmd + " >/dev/null 2>" + log.string()).c_str());
  *err = read_file(log.string());
  fs::remove(log);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

const std::string kQuickstart = std::string(omniloc::source_dir().string()) + "/scenarios/quickstart.json";

}  // namespace

TEST(EglDeviceChoice, AutoTriesCudaDevicesInCudaOrderThenHardwareThenSoftwareThenSurfaceless) {
  // EGL order: software, a non-CUDA render node, CUDA 1, CUDA 0 (drivers list in any order).
  const std::vector<EglDeviceDesc> devs = {dev(0, true), dev(1, false), dev(2, false, 1), dev(3, false, 0)};
  EXPECT_EQ(egl_auto_order(devs, 0), (std::vector<int>{3, 2, 1, 0, -1}));
  // The rotation (a process's pid) picks the GPU it starts at, the others stay as fall-backs.
  EXPECT_EQ(egl_auto_order(devs, 1), (std::vector<int>{2, 3, 1, 0, -1}));
  EXPECT_EQ(egl_auto_order(devs, 1001), (std::vector<int>{2, 3, 1, 0, -1}));
  // Without CUDA devices the hardware devices rotate; software devices never do.
  const std::vector<EglDeviceDesc> mesa = {dev(0, false), dev(1, false), dev(2, true), dev(3, true)};
  EXPECT_EQ(egl_auto_order(mesa, 0), (std::vector<int>{0, 1, 2, 3, -1}));
  EXPECT_EQ(egl_auto_order(mesa, 3), (std::vector<int>{1, 0, 2, 3, -1}));
  EXPECT_EQ(egl_auto_order({}, 7), (std::vector<int>{-1}));
}

TEST(EglDeviceChoice, RequestsAreParsedAndBadOnesNameTheVariable) {
  EXPECT_EQ(parse_egl_device_request(nullptr).kind, EglDeviceRequest::kAuto);
  EXPECT_EQ(parse_egl_device_request("").kind, EglDeviceRequest::kAuto);
  EXPECT_EQ(parse_egl_device_request("auto").kind, EglDeviceRequest::kAuto);
  EXPECT_EQ(parse_egl_device_request("surfaceless").kind, EglDeviceRequest::kSurfaceless);
  const auto r = parse_egl_device_request("12");
  EXPECT_EQ(r.kind, EglDeviceRequest::kIndex);
  EXPECT_EQ(r.index, 12);
  for (const char* bad : {"gpu0", "-1", "1 ", "99999", "0x1"}) {
    try {
      parse_egl_device_request(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.path(), "$OMNILOC_EGL_DEVICE") << bad;
    }
  }
}

TEST(EglDeviceChoice, BackendVariableOverridesTheScenarioAndIsChecked) {
  {
    ScopedEnv env("OMNILOC_GL_BACKEND", nullptr);
    EXPECT_EQ(effective_gl_backend("osmesa"), "osmesa");
  }
  {
    ScopedEnv env("OMNILOC_GL_BACKEND", "egl");
    EXPECT_EQ(effective_gl_backend("osmesa"), "egl");
    Json eff;
    const auto c = CameraConfig::from_json(Json::object(), "/camera", &eff);
    EXPECT_EQ(c.backend, "egl");
    EXPECT_EQ(eff["backend"], "egl");  // the run's config.json says what rendered it
  }
  {
    ScopedEnv env("OMNILOC_GL_BACKEND", "vulkan");
    try {
      effective_gl_backend("osmesa");
      ADD_FAILURE() << "vulkan was accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.path(), "$OMNILOC_GL_BACKEND");
      EXPECT_NE(std::string(e.what()).find("vulkan"), std::string::npos);
    }
  }
}

TEST(EglDevices, AutoOpensAnEnumeratedDeviceAndRecordsWhatItIs) {
  ScopedEnv env("OMNILOC_EGL_DEVICE", nullptr);
  std::vector<EglDeviceDesc> devs;
  try {
    devs = egl_devices();
  } catch (const RuntimeFailure& e) {
    GTEST_SKIP() << "no EGL device enumeration here: " << e.what();
  }
  if (devs.empty()) GTEST_SKIP() << "libEGL lists no device here";
  for (std::size_t i = 0; i < devs.size(); ++i) {
    EXPECT_EQ(devs[i].index, static_cast<int>(i));
    EXPECT_FALSE(devs[i].extensions.empty()) << "device " << i;
  }
  const auto ctx = make_gl_context("egl");
  const GlDeviceInfo& d = ctx->device();
  EXPECT_EQ(d.backend, "egl");
  EXPECT_EQ(d.selection, "auto");
  EXPECT_FALSE(d.renderer.empty());
  EXPECT_FALSE(d.vendor.empty());
  // Some enumerated device renders wherever one is listed (Mesa's software device at least), so
  // auto must not have fallen through to the surfaceless display.
  EXPECT_EQ(d.platform, "device") << d.line();
  ASSERT_GE(d.egl_device, 0);
  ASSERT_LT(d.egl_device, static_cast<int>(devs.size()));
  const Json j = d.to_json();
  EXPECT_EQ(j["egl_device"], d.egl_device);
  EXPECT_EQ(j["renderer"], d.renderer);
}

TEST(EglDevices, AnIndexPicksThatDeviceAndSurfacelessTheMesaDisplay) {
  if (const std::string why = egl_here(); !why.empty()) GTEST_SKIP() << why;
  const auto devs = egl_devices();
  for (const auto& want : devs) {
    ScopedEnv env("OMNILOC_EGL_DEVICE", std::to_string(want.index).c_str());
    try {
      const auto ctx = make_gl_context("egl");
      EXPECT_EQ(ctx->device().egl_device, want.index);
      EXPECT_EQ(ctx->device().selection, "OMNILOC_EGL_DEVICE=" + std::to_string(want.index));
    } catch (const RuntimeFailure& e) {
      // A listed device may refuse (a GPU without a driver for this user); the message says which.
      EXPECT_NE(std::string(e.what()).find("EGL device " + std::to_string(want.index)), std::string::npos) << e.what();
    }
  }
  ScopedEnv env("OMNILOC_EGL_DEVICE", "surfaceless");
  try {
    const auto ctx = make_gl_context("egl");
    EXPECT_EQ(ctx->device().platform, "surfaceless");
    EXPECT_EQ(ctx->device().egl_device, -1);
  } catch (const RuntimeFailure& e) {
    EXPECT_NE(std::string(e.what()).find("surfaceless Mesa display"), std::string::npos) << e.what();
  }
}

TEST(EglDevices, AMissingDeviceIsAnErrorThatNamesIt) {
  ScopedEnv env("OMNILOC_EGL_DEVICE", "97");
  try {
    (void)make_gl_context("egl");
    FAIL() << "device 97 opened";
  } catch (const RuntimeFailure& e) {
    EXPECT_NE(std::string(e.what()).find("OMNILOC_EGL_DEVICE=97"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(gl_backend_problem("egl").empty());
}

TEST(EglDevices, TheSameSceneRendersAlikeOnEveryBackEndHere) {
  // Here every back-end is llvmpipe (OSMesa, Mesa's software device, the surfaceless display), so
  // the pixels must agree exactly; a GPU's may not (docs/camera.md "GPUs"), which is measured by
  // scripts/gpu_check.sh against the runs' statistics instead.
  if (const std::string why = egl_here(); !why.empty()) GTEST_SKIP() << why;
  auto frame = [](const std::string& backend, const char* device) {
    ScopedEnv env("OMNILOC_EGL_DEVICE", device);
    CameraConfig cfg;
    cfg.backend = backend;
    PanoramicCamera cam(cfg, Field::preset("msl2012"));
    if (backend == "egl" && cam.device().renderer.find("llvmpipe") == std::string::npos) return Image();
    Rng rng(3);
    return cam.render(scenes::one_robot(Pose2(-1.0, 0.5, 0.4)), 0, cfg.initial, rng);
  };
  const Image ref = frame("osmesa", nullptr);
  for (const char* device : {"auto", "surfaceless"}) {
    Image img;
    try {
      img = frame("egl", device);
    } catch (const RuntimeFailure& e) {
      continue;  // no surfaceless display here: the fallback test above covers the message
    }
    if (img.rgb.empty()) continue;  // a GPU: not llvmpipe
    EXPECT_EQ(img.rgb, ref.rgb) << "OMNILOC_EGL_DEVICE=" << device;
  }
}

TEST(EglDevices, ValidationFailsWithExit2WhenEglCannotRender) {
  if (!fs::exists("./omniloc")) GTEST_SKIP() << "run from the build folder (ctest does)";
  std::string err;
  // A device this machine does not have.
  EXPECT_EQ(shell("OMNILOC_GL_BACKEND=egl OMNILOC_EGL_DEVICE=97 ./omniloc validate " + kQuickstart, &err), 2) << err;
  EXPECT_NE(err.find("$OMNILOC_GL_BACKEND"), std::string::npos) << err;
  EXPECT_NE(err.find("OMNILOC_EGL_DEVICE=97"), std::string::npos) << err;
  // No EGL vendor at all (glvnd finds no driver): no device, no surfaceless display.
  EXPECT_EQ(shell("OMNILOC_GL_BACKEND=egl __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/none.json ./omniloc validate " + kQuickstart, &err), 2)
      << err;
  EXPECT_NE(err.find("no device could render"), std::string::npos) << err;
  // A malformed variable is named as such.
  EXPECT_EQ(shell("OMNILOC_GL_BACKEND=egl OMNILOC_EGL_DEVICE=first ./omniloc validate " + kQuickstart, &err), 2) << err;
  EXPECT_NE(err.find("$OMNILOC_EGL_DEVICE"), std::string::npos) << err;
  EXPECT_EQ(shell("OMNILOC_GL_BACKEND=directx ./omniloc validate " + kQuickstart, &err), 2) << err;
  EXPECT_NE(err.find("$OMNILOC_GL_BACKEND"), std::string::npos) << err;
  // And where egl renders, the same scenario validates.
  if (egl_here().empty()) {
    EXPECT_EQ(shell("OMNILOC_GL_BACKEND=egl ./omniloc validate " + kQuickstart, &err), 0) << err;
  }
}
