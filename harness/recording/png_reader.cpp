#include "harness/recording/png_reader.hpp"

#include "harness/image_file.hpp"

namespace omniloc::harness {

std::shared_ptr<const Image> read_png(const std::string& path) {
  // The file was found readable before (why_not_readable_file): what fails here is its content.
  return std::make_shared<Image>(read_png_rgb(path));
}

}  // namespace omniloc::harness
