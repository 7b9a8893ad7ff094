# FindIce: ZeroC Ice 3.7 with the C++11 mapping, as Debian packages it (libzeroc-ice-dev,
# zeroc-ice-compilers). Debian ships neither a CMake config nor a pkg-config file.
#
# It is installed with the SAFECASS package config: users who link safecass::middleware need the
# libraries only; building SAFECASS also needs the Slice compiler (component slice2cpp).
#
#   find_package(Ice [REQUIRED] [COMPONENTS slice2cpp])
#
# Defines:
#   Ice_FOUND; with component slice2cpp also Ice_SLICE2CPP_EXECUTABLE, Ice_SLICE_DIR
#   Ice::Ice++11, Ice::IceStorm++11, Ice::IceSSL++11 (imported targets; ICE_CPP11_MAPPING is
#   defined for users)
#   ice_slice2cpp(OUTPUT_VAR <var> SLICE <file.ice>... [OUTPUT_DIR <dir>])
#     runs slice2cpp as a custom command and sets <var> to the generated .cpp and .h files.

find_path(Ice_INCLUDE_DIR Ice/Ice.h)
find_library(Ice_CPP11_LIBRARY NAMES Ice++11)
find_library(Ice_ICESTORM_CPP11_LIBRARY NAMES IceStorm++11)
find_library(Ice_ICESSL_CPP11_LIBRARY NAMES IceSSL++11)
set(_ice_required Ice_INCLUDE_DIR Ice_CPP11_LIBRARY Ice_ICESTORM_CPP11_LIBRARY Ice_ICESSL_CPP11_LIBRARY)
if("slice2cpp" IN_LIST Ice_FIND_COMPONENTS)
  find_program(Ice_SLICE2CPP_EXECUTABLE slice2cpp)
  find_path(Ice_SLICE_DIR Ice/BuiltinSequences.ice PATHS /usr/share/ice/slice /usr/share/slice NO_DEFAULT_PATH)
  list(APPEND _ice_required Ice_SLICE2CPP_EXECUTABLE Ice_SLICE_DIR)
  if(Ice_SLICE2CPP_EXECUTABLE AND Ice_SLICE_DIR)
    set(Ice_slice2cpp_FOUND TRUE)
  endif()
endif()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Ice REQUIRED_VARS ${_ice_required} HANDLE_COMPONENTS)
unset(_ice_required)

if(Ice_FOUND AND NOT TARGET Threads::Threads)
  find_package(Threads REQUIRED)
endif()
if(Ice_FOUND AND NOT TARGET Ice::Ice++11)
  add_library(Ice::Ice++11 UNKNOWN IMPORTED)
  set_target_properties(Ice::Ice++11 PROPERTIES
    IMPORTED_LOCATION ${Ice_CPP11_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES ${Ice_INCLUDE_DIR}
    INTERFACE_COMPILE_DEFINITIONS ICE_CPP11_MAPPING
    INTERFACE_LINK_LIBRARIES Threads::Threads)
  add_library(Ice::IceStorm++11 UNKNOWN IMPORTED)
  set_target_properties(Ice::IceStorm++11 PROPERTIES
    IMPORTED_LOCATION ${Ice_ICESTORM_CPP11_LIBRARY}
    INTERFACE_LINK_LIBRARIES Ice::Ice++11)
  add_library(Ice::IceSSL++11 UNKNOWN IMPORTED)
  set_target_properties(Ice::IceSSL++11 PROPERTIES
    IMPORTED_LOCATION ${Ice_ICESSL_CPP11_LIBRARY}
    INTERFACE_LINK_LIBRARIES Ice::Ice++11)
endif()

function(ice_slice2cpp)
  cmake_parse_arguments(S "" "OUTPUT_VAR;OUTPUT_DIR;ADD_HEADER" "SLICE" ${ARGN})
  set(add_header)
  if(S_ADD_HEADER)
    set(add_header --add-header ${S_ADD_HEADER})
  endif()
  if(NOT S_OUTPUT_DIR)
    set(S_OUTPUT_DIR ${CMAKE_CURRENT_BINARY_DIR}/generated)
  endif()
  file(MAKE_DIRECTORY ${S_OUTPUT_DIR})
  set(outputs)
  foreach(slice IN LISTS S_SLICE)
    get_filename_component(base ${slice} NAME_WE)
    get_filename_component(dir ${slice} DIRECTORY)
    add_custom_command(
      OUTPUT ${S_OUTPUT_DIR}/${base}.cpp ${S_OUTPUT_DIR}/${base}.h
      COMMAND ${Ice_SLICE2CPP_EXECUTABLE} -I${Ice_SLICE_DIR} -I${dir} ${add_header} --output-dir ${S_OUTPUT_DIR} ${slice}
      DEPENDS ${slice} ${S_ADD_HEADER}
      COMMENT "slice2cpp ${base}.ice"
      VERBATIM)
    list(APPEND outputs ${S_OUTPUT_DIR}/${base}.cpp ${S_OUTPUT_DIR}/${base}.h)
  endforeach()
  set(${S_OUTPUT_VAR} ${outputs} PARENT_SCOPE)
endfunction()
