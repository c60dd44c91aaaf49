# `cmake --install BUILD --prefix PREFIX` puts the command-line tool
# (skybake::skybake, which skybake_add_bake in cmake/skybakeAddBake.cmake runs
# as a step of a build) and its image module, the loader library (skybake::formats: LoadLutSet and the manifest, with the
# LutSet of skybake::bake, the CPU twin of skybake::runtime and the errors
# of skybake::core), their headers
# and the runtime GLSL into PREFIX, with a CMake package:
#
#   find_package(skybake REQUIRED)
#   target_link_libraries(my_tool PRIVATE skybake::formats)
#
# Headers keep the source tree's layout under include/skybake/ (so
# `#include "formats/lut_files.h"`, as inside skybake).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(SKYBAKE_INSTALL_INCLUDEDIR ${CMAKE_INSTALL_INCLUDEDIR}/skybake)
set(SKYBAKE_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/skybake)

set_target_properties(skybake_core PROPERTIES EXPORT_NAME core)
set_target_properties(skybake_runtime PROPERTIES EXPORT_NAME runtime)
set_target_properties(skybake_bake PROPERTIES EXPORT_NAME bake)
set_target_properties(skybake_formats PROPERTIES EXPORT_NAME formats)
foreach(target skybake_core skybake_runtime skybake_bake skybake_formats)
  target_include_directories(${target} INTERFACE $<INSTALL_INTERFACE:${SKYBAKE_INSTALL_INCLUDEDIR}>)
endforeach()

# The program, skybake::skybake in the package (skybake_add_bake runs it).
install(TARGETS skybake EXPORT skybakeTargets RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The image module, where plot/image_library.cpp looks beside bin/.
install(TARGETS skybake_images LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/skybake)
install(TARGETS skybake_core skybake_runtime skybake_bake skybake_formats EXPORT skybakeTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
foreach(dir core bake formats shaders_runtime)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir}/ DESTINATION ${SKYBAKE_INSTALL_INCLUDEDIR}/${dir}
          FILES_MATCHING PATTERN "*.h")
endforeach()
install(FILES ${PROJECT_BINARY_DIR}/generated/core/version.h DESTINATION ${SKYBAKE_INSTALL_INCLUDEDIR}/core)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/shaders_runtime/ DESTINATION ${CMAKE_INSTALL_DATADIR}/skybake/shaders_runtime
        FILES_MATCHING PATTERN "*.glsl" PATTERN "*.hlsl" PATTERN "*.metal" PATTERN "*.wgsl" PATTERN "README.md"
        PATTERN "translate" EXCLUDE)

install(EXPORT skybakeTargets NAMESPACE skybake:: DESTINATION ${SKYBAKE_INSTALL_CMAKEDIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/skybakeConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/skybakeConfig.cmake INSTALL_DESTINATION ${SKYBAKE_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/skybakeConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/skybakeConfig.cmake ${PROJECT_BINARY_DIR}/skybakeConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/OpenImageIO.cmake ${PROJECT_SOURCE_DIR}/cmake/skybakeAddBake.cmake
        DESTINATION ${SKYBAKE_INSTALL_CMAKEDIR})
