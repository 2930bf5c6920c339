# `cmake --install BUILD --prefix P` installs the program (P/bin/abcube, host/CMakeLists.txt),
# the Python module (python/CMakeLists.txt) and what a program needs to link the library:
#   P/include/abcube/*.hpp                the public API
#   P/lib/libabcube.a                     abcube::abcube, with the static libraries it links
#   P/lib/libabcube_core.a, libabcube_options.a, libabcube_glad.a
#   P/lib/libabcube_report.a              abcube::report, the comparison report (<abcube/report.hpp>)
#   P/lib/cmake/abcube/abcubeConfig.cmake (+ version file and exported targets)
# so that another project does find_package(abcube REQUIRED) and links abcube::abcube (and
# abcube::report for the report).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(ABCUBE_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/abcube)
install(TARGETS abcube_library abcube_report abcube_options abcube_core abcube_glad EXPORT abcubeTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/abcube DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.hpp")
install(EXPORT abcubeTargets NAMESPACE abcube:: DESTINATION ${ABCUBE_CMAKE_DIR})

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/abcubeConfig.cmake.in
  ${PROJECT_BINARY_DIR}/abcubeConfig.cmake INSTALL_DESTINATION ${ABCUBE_CMAKE_DIR})
# 0.x: the API may change between minor versions.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/abcubeConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/abcubeConfig.cmake ${PROJECT_BINARY_DIR}/abcubeConfigVersion.cmake
  DESTINATION ${ABCUBE_CMAKE_DIR})
