# Finds the few OpenCV 4 modules curvesfm uses, as Debian ships them split into
# libopencv-<module>-dev packages. Debian's OpenCVConfig.cmake only comes with the
# libopencv-dev meta package, which drags in VTK, Qt and MPI; we do not need them.
#
# Defines an imported target OpenCV::<module> for every requested component.
#   find_package(OpenCVLite REQUIRED COMPONENTS core imgproc imgcodecs)

find_path(OpenCVLite_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4)

set(OpenCVLite_LIBRARIES)
foreach(module IN LISTS OpenCVLite_FIND_COMPONENTS)
  find_library(OpenCVLite_${module}_LIBRARY NAMES opencv_${module})
  if(OpenCVLite_INCLUDE_DIR AND OpenCVLite_${module}_LIBRARY)
    set(OpenCVLite_${module}_FOUND TRUE)
    if(NOT TARGET OpenCV::${module})
      add_library(OpenCV::${module} UNKNOWN IMPORTED)
      set_target_properties(OpenCV::${module} PROPERTIES
        IMPORTED_LOCATION "${OpenCVLite_${module}_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${OpenCVLite_INCLUDE_DIR}")
    endif()
    list(APPEND OpenCVLite_LIBRARIES OpenCV::${module})
  endif()
endforeach()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenCVLite
  REQUIRED_VARS OpenCVLite_INCLUDE_DIR
  HANDLE_COMPONENTS
  REASON_FAILURE_MESSAGE "run scripts/install-deps.sh (needs libopencv-<module>-dev)")
