#include "sim/render/gl_device_info.hpp"

namespace omniloc::sim {

Json GlDeviceInfo::to_json() const {
  Json j{{"backend", backend}, {"platform", platform}, {"vendor", vendor}, {"renderer", renderer}, {"version", version}};
  if (backend == "egl") {
    j["egl_device"] = egl_device;
    j["cuda_device"] = cuda_device;
    j["drm_node"] = drm_node;
    j["selection"] = selection;
  }
  return j;
}

std::string GlDeviceInfo::line() const {
  std::string s = backend + " (" + platform;
  if (egl_device >= 0) s += " " + std::to_string(egl_device);
  if (cuda_device >= 0) s += ", CUDA device " + std::to_string(cuda_device);
  if (!drm_node.empty()) s += ", " + drm_node;
  s += "): " + vendor + ", " + renderer + ", GL " + version;
  if (!selection.empty()) s += " [" + selection + "]";
  return s;
}

}  // namespace omniloc::sim
