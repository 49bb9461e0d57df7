#include "core/error.hpp"

#include <cstring>

namespace omniloc {

IoError::IoError(const std::string& action, std::string path, int err) : IoError(action, std::move(path), std::string(std::strerror(err))) {}

IoError::IoError(const std::string& action, std::string path, const std::string& why)
    : RuntimeFailure(action + " " + path + ": " + why), path_(std::move(path)) {}

}  // namespace omniloc
