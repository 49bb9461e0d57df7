#pragma once
// A recording's frame images (images/r<robot>_<k>.png, lossless) read back as the Image a
// localizer is given (RGB, row-major).
#include <memory>
#include <string>

#include "localization/localizer.hpp"

namespace omniloc::harness {

/// The image at `path`; a ConfigError naming it when its content is not a PNG libpng can read (the
/// file was found readable).
std::shared_ptr<const Image> read_png(const std::string& path);

}  // namespace omniloc::harness
