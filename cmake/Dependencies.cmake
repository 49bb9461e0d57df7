# All dependencies come from Debian 12 packages (scripts/install-deps.sh).
find_package(Threads REQUIRED)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(box2d 2.4 REQUIRED)

# OpenCV: Debian's split packages (libopencv-{core,imgproc,imgcodecs}-dev) ship no CMake config,
# so locate headers and the libraries directly. The program links core and imgproc only: Debian's
# imgcodecs pulls in GDAL, GDCM, Poppler, HDF5 and about 120 more shared objects, loaded at every
# start (harness/image_file.hpp); PNG and JPEG files go through libpng and libjpeg-turbo directly,
# with OpenCV's settings. imgcodecs stays for the test that proves the bytes equal
# (omniloc::opencv_imgcodecs, tests only).
find_path(OPENCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4 REQUIRED)
foreach(m core imgproc imgcodecs)
  find_library(OPENCV_${m}_LIB NAMES opencv_${m} REQUIRED)
endforeach()
add_library(omniloc::opencv INTERFACE IMPORTED)
target_include_directories(omniloc::opencv SYSTEM INTERFACE ${OPENCV_INCLUDE_DIR})
target_link_libraries(omniloc::opencv INTERFACE ${OPENCV_imgproc_LIB} ${OPENCV_core_LIB})
add_library(omniloc::opencv_imgcodecs INTERFACE IMPORTED)
target_link_libraries(omniloc::opencv_imgcodecs INTERFACE ${OPENCV_imgcodecs_LIB} omniloc::opencv)
find_package(PNG REQUIRED)
find_package(JPEG REQUIRED)

# OSMesa and EGL are loaded at run time with dlopen (sim/render/gl_context.cpp, one back-end class
# each): each back-end resolves its own GL entry points, so neither glvnd's libGL nor libOSMesa is
# linked and their gl* symbols never clash. Only their headers are needed to build (libosmesa6-dev,
# libegl-dev); they sit in the compiler's default search path, so these two look-ups only stop the
# configuration early, with the header's name, when a package is missing.
find_path(OSMESA_INCLUDE_DIR GL/osmesa.h REQUIRED)
find_path(EGL_INCLUDE_DIR EGL/egl.h REQUIRED)

# SHA-256 of an external localizer's program and script (summary.json provenance).
find_package(OpenSSL REQUIRED COMPONENTS Crypto)
# gzip of a recording's frames (harness/recording/format/gzip.cpp, docs/recording.md).
find_package(ZLIB REQUIRED)
# simdjson: the recording reader's fast path (harness/recording/frames_reader.cpp; docs/performance.md "Replay").
find_package(simdjson REQUIRED)
