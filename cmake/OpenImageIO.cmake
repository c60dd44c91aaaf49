# Debian's OpenImageIO config lists /usr/include/opencv4 among its include
# directories although the package does not depend on OpenCV; CMake refuses
# to generate with a missing include path, so drop it from the imported targets.
find_package(OpenImageIO CONFIG REQUIRED)
foreach(target OpenImageIO::OpenImageIO OpenImageIO::OpenImageIO_Util)
  if(TARGET ${target})
    foreach(property INTERFACE_INCLUDE_DIRECTORIES INTERFACE_SYSTEM_INCLUDE_DIRECTORIES)
      get_target_property(dirs ${target} ${property})
      if(dirs)
        list(FILTER dirs EXCLUDE REGEX "opencv4")
        set_target_properties(${target} PROPERTIES ${property} "${dirs}")
      endif()
    endforeach()
  endif()
endforeach()
