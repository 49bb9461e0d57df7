#pragma once
// What a GL context renders on (back-end, EGL device, GL strings): the provenance summary.json
// records and logs show. Below both the contexts (gl_context.hpp) and the choice of an EGL device
// (egl_device.hpp), which fills it in.
#include <string>

#include "core/json_reader.hpp"

namespace omniloc::sim {

/// Where and on what a GL context renders: written to summary.json's provenance and logged.
struct GlDeviceInfo {
  std::string backend;    ///< "osmesa" or "egl"
  std::string platform;   ///< "osmesa", "device" (EGL_EXT_platform_device) or "surfaceless" (EGL_PLATFORM_SURFACELESS_MESA)
  int egl_device = -1;    ///< index in the EGL device enumeration, -1 off the device platform
  int cuda_device = -1;   ///< the device's CUDA ordinal (EGL_NV_device_cuda), -1 where it has none
  std::string drm_node;   ///< DRM render node or device file (EGL_EXT_device_drm), empty where none
  std::string vendor, renderer, version;  ///< glGetString(GL_VENDOR / GL_RENDERER / GL_VERSION)
  std::string selection;  ///< how it was chosen, e.g. "auto" or "OMNILOC_EGL_DEVICE=1"
  Json to_json() const;
  std::string line() const;  ///< one line for logs
};

}  // namespace omniloc::sim
