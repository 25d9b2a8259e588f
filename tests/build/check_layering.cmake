# The build's layering (cmake/ModuleLayers.cmake) refuses upward includes: a probe file including
# a header is compiled (syntax only) with one module's include path; the upward includes must fail
# with "No such file or directory" and the allowed ones compile.
#
# cmake -DCXX=... -DLAYERS=<build>/layers -DSYSTEM_INCLUDES="a;b" -DSCRATCH=<dir> -P this file

set(refused
    "io|keyplace/mapping/global_map.hpp"
    "features|keyplace/registration/icp.hpp"
    "place|keyplace/slam/online_slam.hpp"
    "mapping|keyplace/localization/relocalizer.hpp"
    "mapping|config/section_tables.hpp"
    "slam|keyplace/eval/relocalization.hpp"
    # store and localization see config's public header, not every module through it
    "store|keyplace/localization/relocalizer.hpp"
    "store|config/section_tables.hpp"
    "localization|keyplace/eval/relocalization.hpp")
set(allowed
    "io|keyplace/io/carmen_log.hpp"
    "io|io/atomic_file.hpp"
    "mapping|keyplace/features/flirt.hpp"
    "slam|keyplace/place/place_recognizer.hpp"
    "store|keyplace/config/config.hpp"
    "localization|keyplace/store/map_file.hpp"
    "config|config/section_tables.hpp")

set(flags -std=c++17 -fsyntax-only)
foreach(directory IN LISTS SYSTEM_INCLUDES)
  list(APPEND flags -isystem ${directory})
endforeach()
file(MAKE_DIRECTORY ${SCRATCH})

# Sets <out_var> to TRUE when <header> compiles within <module>'s layer; <log_var> gets the output.
function(compiles_in_layer module header out_var log_var)
  string(MAKE_C_IDENTIFIER "${module}_${header}" name)
  set(probe ${SCRATCH}/${name}.cpp)
  file(WRITE ${probe} "#include \"${header}\"\n")
  execute_process(
    COMMAND ${CXX} ${flags} -I${LAYERS}/${module}/include -I${LAYERS}/${module}/src ${probe}
    RESULT_VARIABLE result OUTPUT_VARIABLE output ERROR_VARIABLE output)
  if(result EQUAL 0)
    set(${out_var} TRUE PARENT_SCOPE)
  else()
    set(${out_var} FALSE PARENT_SCOPE)
  endif()
  set(${log_var} "${output}" PARENT_SCOPE)
endfunction()

set(failures 0)
foreach(case IN LISTS refused)
  string(REPLACE "|" ";" parts "${case}")
  list(GET parts 0 module)
  list(GET parts 1 header)
  compiles_in_layer(${module} ${header} compiled log)
  string(REPLACE "." "\\." header_pattern "${header}")
  if(compiled OR NOT log MATCHES "${header_pattern}: No such file or directory")
    message(SEND_ERROR "${module} may include ${header}: the layering should refuse it\n${log}")
    math(EXPR failures "${failures} + 1")
  else()
    message(STATUS "refused: ${module} -> ${header}")
  endif()
endforeach()
foreach(case IN LISTS allowed)
  string(REPLACE "|" ";" parts "${case}")
  list(GET parts 0 module)
  list(GET parts 1 header)
  compiles_in_layer(${module} ${header} compiled log)
  if(NOT compiled)
    message(SEND_ERROR "${module} cannot include ${header}, which its layer allows:\n${log}")
    math(EXPR failures "${failures} + 1")
  else()
    message(STATUS "allowed: ${module} -> ${header}")
  endif()
endforeach()
file(REMOVE_RECURSE ${SCRATCH})
if(failures GREATER 0)
  message(FATAL_ERROR "${failures} layering check(s) failed")
endif()
