# Included by the build-time generators (cmake/version.cmake, cmake/world_fingerprint.cmake): writes
# `content` to OUT only when it differs, so an unchanged header recompiles nothing.
if(EXISTS "${OUT}")
  file(READ "${OUT}" old)
else()
  set(old "")
endif()
if(NOT old STREQUAL content)
  file(WRITE "${OUT}" "${content}")
endif()
