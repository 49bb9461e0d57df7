# Install rules and the Debian package (docs/package.md; scripts/package.sh runs cpack). The layout
# under the prefix mirrors the source tree's, so core/install_paths.cpp finds everything at
# <bin>/../share/omniloc and the results package (share/omniloc/python/omniloc) finds results/reference
# two folders above itself (omniloc/core/paths.py), as in a clone:
#   bin/omniloc
#   share/omniloc/{data,scenarios,results/reference,python/omniloc,scripts,clients}
#   share/doc/omniloc/{README.md,*.md,img/}
# Only the omniloc binary is installed: no tests, benchmarks or client examples' builds.
include(GNUInstallDirs)
# `cmake --install` and cpack would otherwise build `all` (every test and benchmark, minutes) first;
# only omniloc is installed, and scripts/package.sh builds that target before cpack.
set(CMAKE_SKIP_INSTALL_ALL_DEPENDENCY ON)
set(OMNILOC_SHARE ${CMAKE_INSTALL_DATADIR}/omniloc)

install(TARGETS omniloc RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# data/: field presets, noise profiles, recordings; scenarios/: every shipped scenario and sweep.
install(DIRECTORY data scenarios DESTINATION ${OMNILOC_SHARE})
install(DIRECTORY results/reference/ DESTINATION ${OMNILOC_SHARE}/results/reference)
# The results package: `omniloc report | gate | compare | paper-table` run
# `python3 -m omniloc.commands.<name>` with PYTHONPATH=share/omniloc/python (docs/architecture.md).
# Its tests (python/tests) and mypy.ini stay in the tree.
install(DIRECTORY python/omniloc DESTINATION ${OMNILOC_SHARE}/python
        PATTERN __pycache__ EXCLUDE PATTERN *.pyc EXCLUDE)
# docs/ci.md's recipe runner (the clean-root stage runs it against the installed package).
install(PROGRAMS scripts/ci_recipe.py DESTINATION ${OMNILOC_SHARE}/scripts)
# What users import to write an external localizer: the Python and C++ clients and their examples
# (source only; the clients' own tests stay in the tree).
install(DIRECTORY clients/python clients/cpp DESTINATION ${OMNILOC_SHARE}/clients
        PATTERN __pycache__ EXCLUDE PATTERN *.pyc EXCLUDE)
install(DIRECTORY docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR} FILES_MATCHING PATTERN *.md PATTERN *.png PATTERN *.svg PATTERN *.jpg
        PATTERN foxglove_layout.json)  # the layout for omniloc export's MCAP files (docs/viewer.md section 8)
install(FILES README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})

# --- Debian package (CPack DEB) -----------------------------------------------------------------
set(OMNILOC_PACKAGE_MAINTAINER "omniloc maintainers <maintainers@users.noreply.h-seed-c2ec5b5d.example>"
    CACHE STRING "Maintainer field of the .deb")
set(OMNILOC_PACKAGE_HOMEPAGE "" CACHE STRING "Homepage field of the .deb (left out when empty)")
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME omniloc)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_PACKAGE_CONTACT "${OMNILOC_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${OMNILOC_PACKAGE_MAINTAINER}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "simulation and benchmark harness for omnidirectional-vision robot localization")
set(CPACK_PACKAGE_DESCRIPTION "Runs RoboCup MSL scenarios headless: a Box2D world, an off-screen renderer of each robot's
catadioptric panorama, the papers' localization pipelines (or a user's external localizer over
olp/1) and the scoring against ground truth; sweeps, comparisons and CI gates of the results.
Ships the field presets, scenarios, reference results, the Python clients and the results package.")
if(OMNILOC_PACKAGE_HOMEPAGE)
  set(CPACK_DEBIAN_PACKAGE_HOMEPAGE "${OMNILOC_PACKAGE_HOMEPAGE}")
endif()
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # omniloc_<version>_<arch>.deb
set(CPACK_STRIP_FILES ON)
# Depends: dpkg-shlibdeps reads the linked libraries (OpenCV, Box2D, OpenSSL, zlib, libstdc++...);
# what is loaded at run time is invisible to it and named here: OSMesa (dlopen'ed by
# sim/render/gl_context.cpp, the default renderer) and python3 (compare, gate, report).
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "libosmesa6, python3")
# libegl1 (libEGL.so.1, dlopen'ed by sim/render/egl_device.cpp; it pulls Mesa's EGL vendor): GPU
# rendering. python3-matplotlib: the report's figures.
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "python3-matplotlib, libegl1")
include(CPack)
