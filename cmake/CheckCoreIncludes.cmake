# Fails the configure step when a core/ header or source includes anything but the standard
# library, Eigen (its FFT module included), or other core/ headers: core/ must stay free of ROS,
# MRPT and OctoMap.
function(check_core_includes root)
  file(GLOB_RECURSE core_files
    "${root}/include/evidential_slam/core/*.h"
    "${root}/src/core/*.cpp" "${root}/src/core/*.h")
  set(violations "")
  foreach(f ${core_files})
    file(STRINGS "${f}" lines REGEX "^[ \t]*#[ \t]*include")
    foreach(line ${lines})
      if(line MATCHES "#[ \t]*include[ \t]*\"evidential_slam/core/")
        continue()
      elseif(line MATCHES "#[ \t]*include[ \t]*<Eigen/")
        continue()
      elseif(line MATCHES "#[ \t]*include[ \t]*<unsupported/Eigen/FFT>")
        # Eigen's FFT module (core/fusion's map alignment)
        continue()
      elseif(line MATCHES "#[ \t]*include[ \t]*<[a-z_0-9]+>")
        # <vector>, <cmath>, ...: standard headers have no directory part
        continue()
      endif()
      string(APPEND violations "\n  ${f}: ${line}")
    endforeach()
  endforeach()
  if(violations)
    message(FATAL_ERROR "core/ may include only the standard library, Eigen and core/ headers:${violations}")
  endif()
endfunction()
