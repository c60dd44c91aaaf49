# skybake_add_bake(TARGET name ATMOSPHERE file-or-preset OUTPUT_DIR dir
#                  [SCENE file] [OPTIONS option...])
#
# Bakes a table set as a step of a build, with the installed skybake: a
# custom command that runs `skybake bake ATMOSPHERE -o OUTPUT_DIR`, whose
# output is OUTPUT_DIR/skybake.json (the manifest, which a bake writes
# last), and a target NAME, built by default, that depends on it.
#
# skybake writes a depfile (`bake --depfile`) naming the files it read, the
# atmosphere file and the scene file, so that the build runs the command
# again only when one of them, or the skybake program, changes. When it runs
# and the set is up to date for its inputs (the manifest's inputs hash: a
# comment edited, a file saved unchanged), skybake leaves the set as it is
# within milliseconds; the command then touches the manifest, so that the
# build tool sees it newer than its inputs.
#
# ATMOSPHERE and SCENE are named as on skybake's command line (a preset such
# as `earth`, or a path, relative to the current source directory);
# OUTPUT_DIR is relative to the current binary directory. OPTIONS go to
# `skybake bake` as they are (for example `--format ktx2 --half`).
#
# Each call is one ordinary custom command: a build that distributes or
# caches custom commands distributes or caches the bakes (docs/cli.md).
function(skybake_add_bake)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "TARGET;ATMOSPHERE;OUTPUT_DIR;SCENE" "OPTIONS")
  foreach(required TARGET ATMOSPHERE OUTPUT_DIR)
    if(NOT arg_${required})
      message(FATAL_ERROR "skybake_add_bake: ${required} is required")
    endif()
  endforeach()
  if(arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "skybake_add_bake: unknown arguments ${arg_UNPARSED_ARGUMENTS}")
  endif()
  if(CMAKE_VERSION VERSION_LESS 3.20)
    message(FATAL_ERROR "skybake_add_bake: needs CMake 3.20 (DEPFILE with every generator)")
  endif()
  get_filename_component(output_dir "${arg_OUTPUT_DIR}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_BINARY_DIR}")
  set(manifest "${output_dir}/skybake.json")
  set(depfile "${CMAKE_CURRENT_BINARY_DIR}/${arg_TARGET}.skybake.d")
  set(scene)
  if(arg_SCENE)
    set(scene --scene "${arg_SCENE}")
  endif()
  add_custom_command(
    OUTPUT "${manifest}"
    COMMAND skybake::skybake bake "${arg_ATMOSPHERE}" -o "${output_dir}" ${scene} --depfile "${depfile}"
            ${arg_OPTIONS}
    COMMAND "${CMAKE_COMMAND}" -E touch_nocreate "${manifest}"
    DEPENDS "$<TARGET_FILE:skybake::skybake>"
    DEPFILE "${depfile}"
    WORKING_DIRECTORY "${CMAKE_CURRENT_SOURCE_DIR}"
    COMMENT "skybake bake ${arg_ATMOSPHERE} -o ${output_dir}"
    VERBATIM)
  add_custom_target(${arg_TARGET} ALL DEPENDS "${manifest}")
endfunction()
