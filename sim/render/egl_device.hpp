#pragma once
// Which EGL device the "egl" back-end renders on (docs/camera.md "GPUs").
//
// Devices are listed with EGL_EXT_device_enumeration (glvnd merges every vendor's list: NVIDIA's
// GPUs, Mesa's hardware render nodes and Mesa's software device) and one is opened with
// EGL_EXT_platform_device; where no device can be opened, Mesa's surfaceless display is the last
// resort. The choice follows OMNILOC_EGL_DEVICE:
//   unset or "auto"  GPUs first: the devices CUDA sees (EGL_NV_device_cuda, in CUDA order, so a
//                    Slurm task's CUDA_VISIBLE_DEVICES is honoured), then other hardware devices,
//                    then software devices, then the surfaceless display. With several GPUs a
//                    process starts at the one numbered (pid mod count), so the runs of a -j N
//                    sweep spread over them and share them when N is larger; the first that
//                    creates a context is used.
//   "<n>"            EGL device n of the enumeration (`omniloc gl-devices` lists them), nothing else.
//   "surfaceless"    the surfaceless display only (the back-end's behaviour before devices).
// OMNILOC_GL_BACKEND ("osmesa" or "egl") overrides every scenario's camera.backend (whole sweeps).
#include <string>
#include <vector>

#include "core/json_reader.hpp"

namespace omniloc::sim {

/// One entry of the EGL device enumeration.
struct EglDeviceDesc {
  int index = -1;          ///< position in eglQueryDevicesEXT's list
  std::string extensions;  ///< the device's extension string
  bool software = false;   ///< EGL_MESA_device_software (llvmpipe)
  int cuda_device = -1;    ///< EGL_CUDA_DEVICE_NV where the driver answers, else -1
  std::string drm_node;    ///< render node, else DRM device file, else empty
};

/// OMNILOC_EGL_DEVICE read: kind auto / index / surfaceless.
struct EglDeviceRequest {
  enum Kind { kAuto, kIndex, kSurfaceless } kind = kAuto;
  int index = -1;
  std::string text;  ///< as given, for messages ("" when unset)
};

/// Parses OMNILOC_EGL_DEVICE's value (nullptr: unset). Throws ConfigError naming the variable.
EglDeviceRequest parse_egl_device_request(const char* value);

/// The order in which "auto" tries the devices: positions in `devices`, -1 standing for the
/// surfaceless display (always last). `rotation` (the pid) picks the GPU a process starts at.
std::vector<int> egl_auto_order(const std::vector<EglDeviceDesc>& devices, long rotation);

/// The EGL device enumeration of this machine (loads libEGL). Throws RuntimeFailure when libEGL
/// or EGL_EXT_device_enumeration is missing; an empty list is not an error.
std::vector<EglDeviceDesc> egl_devices();

/// The back-end a camera uses: OMNILOC_GL_BACKEND when set (checked: ConfigError naming the
/// variable), else `configured`.
std::string effective_gl_backend(const std::string& configured);

/// Whether `backend` can create a context here, tried once per process (and per OMNILOC_EGL_DEVICE
/// value): empty when it can, else why not. Validation turns a non-empty answer into exit 2.
std::string gl_backend_problem(const std::string& backend);

}  // namespace omniloc::sim
