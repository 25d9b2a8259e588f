# The library's layering (docs/ARCHITECTURE.md, "Modules"), enforced by the build: each module is
# compiled as its own OBJECT library whose include path holds only its own headers, those of the
# modules it may use, and the headers those include in turn. An include of any other module's
# header (an upward include) then fails to compile with "No such file or directory".
#
# The headers are symbolic links under ${CMAKE_BINARY_DIR}/layers/<module>/{include,src}/, made at
# configure time; the same paths as in the source tree, so the code is unchanged.

# Which modules each module may include (besides itself): their public headers
# (include/keyplace/<module>/) and internal ones (src/<module>/). config composes every module's
# configuration; store (the configuration recorded in a map), slam and localization (their node
# cores take a whole Config) use it back, "config:public": its public headers only, and through them only
# the headers those need.
set(KEYPLACE_MODULE_USES_common "")
set(KEYPLACE_MODULE_USES_io common)
set(KEYPLACE_MODULE_USES_features common io)
set(KEYPLACE_MODULE_USES_registration common io)
set(KEYPLACE_MODULE_USES_mapping common io features registration)
set(KEYPLACE_MODULE_USES_place common io features mapping)
set(KEYPLACE_MODULE_USES_store common io mapping config:public)
set(KEYPLACE_MODULE_USES_slam common io features registration mapping place store config:public)
set(KEYPLACE_MODULE_USES_localization common io features mapping place store config:public)
set(KEYPLACE_MODULE_USES_eval common io features registration mapping place localization slam)
set(KEYPLACE_MODULE_USES_config common io features registration mapping place slam localization
    eval)
set(KEYPLACE_MODULES common io features registration mapping place store slam localization eval
    config)

# The quoted includes of a header that name a file of the tree (include/ or src/), as paths
# relative to the project; others (generated, system) are not followed.
function(keyplace_included_headers header out_var)
  file(STRINGS ${PROJECT_SOURCE_DIR}/${header} lines REGEX "^#include \"")
  set(found "")
  foreach(line IN LISTS lines)
    string(REGEX REPLACE "^#include \"([^\"]+)\".*" "\\1" included "${line}")
    if(EXISTS ${PROJECT_SOURCE_DIR}/include/${included})
      list(APPEND found include/${included})
    elseif(EXISTS ${PROJECT_SOURCE_DIR}/src/${included})
      list(APPEND found src/${included})
    endif()
  endforeach()
  set(${out_var} ${found} PARENT_SCOPE)
endfunction()

# Links into ${CMAKE_BINARY_DIR}/layers/<module>/ every header <module> may include; sets
# <out_var> to the include directories to compile it with.
function(keyplace_stage_module_layer module out_var)
  set(pending "")
  foreach(allowed IN LISTS module KEYPLACE_MODULE_USES_${module})
    string(REPLACE ":public" "" allowed_module ${allowed})
    set(patterns ${PROJECT_SOURCE_DIR}/include/keyplace/${allowed_module}/*.hpp)
    if(allowed STREQUAL allowed_module)
      list(APPEND patterns ${PROJECT_SOURCE_DIR}/src/${allowed_module}/*.hpp)
    endif()
    file(GLOB_RECURSE headers RELATIVE ${PROJECT_SOURCE_DIR} CONFIGURE_DEPENDS ${patterns})
    list(APPEND pending ${headers})
  endforeach()
  set(staged "")
  while(pending)
    list(POP_FRONT pending header)
    if(header IN_LIST staged)
      continue()
    endif()
    list(APPEND staged ${header})
    # A new include in a header can widen what the module needs: configure again then.
    set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
                 ${PROJECT_SOURCE_DIR}/${header})
    keyplace_included_headers(${header} included)
    list(APPEND pending ${included})
  endwhile()
  set(root ${CMAKE_BINARY_DIR}/layers/${module})
  file(REMOVE_RECURSE ${root})
  foreach(header IN LISTS staged)
    get_filename_component(directory ${root}/${header} DIRECTORY)
    file(MAKE_DIRECTORY ${directory})
    file(CREATE_LINK ${PROJECT_SOURCE_DIR}/${header} ${root}/${header} SYMBOLIC)
  endforeach()
  set(${out_var} ${root}/include ${root}/src PARENT_SCOPE)
endfunction()
