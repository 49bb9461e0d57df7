// `omniloc gl-devices`: the EGL devices and where each GL back-end renders.
#include "apps/commands.hpp"

#include <iostream>

#include "core/error.hpp"
#include "sim/render/egl_device.hpp"
#include "sim/render/gl_context.hpp"

namespace omniloc::app {

const cli::Command kGlDevices{"gl-devices", "", 0, 0,
                               "The EGL devices of this machine (EGL_EXT_device_enumeration) and the device each GL back-end\n"
                               "renders on under the current OMNILOC_EGL_DEVICE; exit 1 when \"egl\" cannot render.",
                               {}};

int cmd_gl_devices(const cli::Args&) {
  std::vector<sim::EglDeviceDesc> devs;
  try {
    devs = sim::egl_devices();
  } catch (const RuntimeFailure& e) {
    std::cout << "no EGL device enumeration: " << e.what() << "\n";
  }
  std::cout << devs.size() << " EGL device(s)\n";
  for (const auto& d : devs)
    std::cout << "  " << d.index << ": " << (d.software ? "software" : "hardware") << (d.cuda_device >= 0 ? ", CUDA device " + std::to_string(d.cuda_device) : "")
              << (d.drm_node.empty() ? "" : ", " + d.drm_node) << "\n    " << d.extensions << "\n";
  int rc = 0;
  for (const std::string& backend : sim::gl_backends()) {
    try {
      const auto ctx = sim::make_gl_context(backend);
      std::cout << backend << " renders on " << ctx->device().line() << "\n";
    } catch (const RuntimeFailure& e) {
      std::cout << backend << " cannot render: " << e.what() << "\n";
      if (backend == "egl") rc = 1;
    }
  }
  return rc;
}

}  // namespace omniloc::app
