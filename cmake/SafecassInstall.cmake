# Installation and export of the SAFECASS modules: `find_package(safecass [COMPONENTS ...])` and
# pkg-config for users (docs/contributing.md, "Adding a module").
#
#   safecass_install_module(<module> [PACKAGES <package>...] [DEBIAN <deb-package>...])
#
# installs target safecass_<module> (static library) as `safecass::<module>`, its public headers
# (<module's folder>/include/), its export file and a pkg-config file `safecass-<module>.pc`, all in
# the `dev` install component. PACKAGES are what the installed config finds with find_dependency()
# before it loads the module (a CMake config package, or a Find module installed with the config:
# Ice, Sodium). DEBIAN are the Debian packages the `-dev` package then depends on.
#
# One line per module, in dependency order (a module after the modules it links). A module whose
# target was not built (an option is off) is known but not installed: asking for it as a component
# says so. safecass_install_package() writes the package config once every module is listed.

include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(SAFECASS_CMAKE_INSTALL_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/safecass)
set_property(GLOBAL PROPERTY SAFECASS_KNOWN_MODULES "")
set_property(GLOBAL PROPERTY SAFECASS_INSTALLED_MODULES "")
set_property(GLOBAL PROPERTY SAFECASS_MODULE_CONFIG "")
set_property(GLOBAL PROPERTY SAFECASS_DEBIAN_DEPENDS "")

# The link flags of an external library for a pkg-config file: an imported target becomes its file
# and its own dependencies; project-internal and build-only items are left out.
function(_safecass_pc_link_flags item out)
  set(flags)
  if(item MATCHES "^\\$<" OR item MATCHES "^safecass" OR item STREQUAL "")
    # generator expressions (build-only warnings) and our own modules (pkg-config Requires)
  elseif(TARGET ${item})
    get_target_property(type ${item} TYPE)
    if(NOT type STREQUAL "INTERFACE_LIBRARY")
      get_target_property(location ${item} IMPORTED_LOCATION)
      if(NOT location)  # a package that sets only per-configuration locations (fmt, for one)
        get_target_property(configurations ${item} IMPORTED_CONFIGURATIONS)
        if(configurations)
          list(GET configurations 0 configuration)
          get_target_property(location ${item} IMPORTED_LOCATION_${configuration})
        endif()
      endif()
      if(location)
        list(APPEND flags ${location})
      endif()
    endif()
    get_target_property(deps ${item} INTERFACE_LINK_LIBRARIES)
    if(deps)
      foreach(dep IN LISTS deps)
        _safecass_pc_link_flags("${dep}" sub)
        list(APPEND flags ${sub})
      endforeach()
    endif()
  elseif(IS_ABSOLUTE "${item}" OR item MATCHES "^-")
    list(APPEND flags ${item})
  elseif(item MATCHES "::")
    message(FATAL_ERROR "safecass_install_module: ${item} is not a target here: list its package in PACKAGES")
  else()
    list(APPEND flags -l${item})
  endif()
  set(${out} ${flags} PARENT_SCOPE)
endfunction()

function(safecass_install_module module)
  cmake_parse_arguments(M "" "" "PACKAGES;DEBIAN" ${ARGN})
  set(target safecass_${module})
  set_property(GLOBAL APPEND PROPERTY SAFECASS_KNOWN_MODULES ${module})
  if(NOT TARGET ${target})
    return()  # not built in this configuration: a known component that is not installed
  endif()
  get_property(installed GLOBAL PROPERTY SAFECASS_INSTALLED_MODULES)
  # The packages' imported targets, visible here for the pkg-config link flags (they are
  # directory-scoped, and the module's folder found them for itself).
  foreach(package IN LISTS M_PACKAGES)
    find_package(${package} QUIET)
  endforeach()

  # The modules it links (safecass::x or safecass_x), which must be installed before it.
  get_target_property(links ${target} LINK_LIBRARIES)
  set(requires)
  set(external)
  foreach(item IN LISTS links)
    if(item MATCHES "^safecass(::|_)([a-z0-9_]+)$" AND NOT CMAKE_MATCH_2 STREQUAL "warnings")
      set(dep ${CMAKE_MATCH_2})
      if(NOT dep IN_LIST installed)
        message(FATAL_ERROR "safecass_install_module(${module}): it links safecass::${dep}, which must be "
                            "listed before it")
      endif()
      list(APPEND requires ${dep})
    else()
      _safecass_pc_link_flags("${item}" flags)
      list(APPEND external ${flags})
    endif()
  endforeach()
  list(REMOVE_DUPLICATES requires)
  list(REMOVE_DUPLICATES external)

  set_target_properties(${target} PROPERTIES EXPORT_NAME ${module})
  install(TARGETS ${target} EXPORT safecass-${module}-targets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
          INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  # `cmake --install --strip` and the packages (CPACK_STRIP_FILES) drop the debug information of the
  # static libraries, keeping their symbol tables, as Debian does for -dev packages.
  install(CODE "if(CMAKE_INSTALL_DO_STRIP)
  execute_process(COMMAND \"${CMAKE_STRIP}\" --strip-debug
    \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR}/$<TARGET_FILE_NAME:${target}>\")
endif()" COMPONENT dev)
  install(EXPORT safecass-${module}-targets NAMESPACE safecass:: DESTINATION ${SAFECASS_CMAKE_INSTALL_DIR}
          COMPONENT dev)
  get_target_property(source_dir ${target} SOURCE_DIR)
  if(EXISTS ${source_dir}/include)
    install(DIRECTORY ${source_dir}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev
            FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h")
  endif()

  # pkg-config: relocatable (paths relative to the .pc file), external libraries in Libs because
  # the libraries are static.
  file(RELATIVE_PATH to_prefix /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
  string(REGEX REPLACE "/$" "" to_prefix "${to_prefix}")
  set(pc_requires)
  foreach(dep IN LISTS requires)
    list(APPEND pc_requires safecass-${dep})
  endforeach()
  list(JOIN pc_requires ", " pc_requires)
  list(JOIN external " " pc_external)
  file(RELATIVE_PATH include_rel /prefix /prefix/${CMAKE_INSTALL_INCLUDEDIR})
  file(RELATIVE_PATH lib_rel /prefix /prefix/${CMAKE_INSTALL_LIBDIR})
  set(pc "${CMAKE_CURRENT_BINARY_DIR}/pkgconfig/safecass-${module}.pc")
  file(GENERATE OUTPUT ${pc} CONTENT
"prefix=\${pcfiledir}/${to_prefix}
includedir=\${prefix}/${include_rel}
libdir=\${prefix}/${lib_rel}

Name: safecass-${module}
Description: SAFECASS ${module} module (${PROJECT_DESCRIPTION})
Version: ${PROJECT_VERSION}
Requires: ${pc_requires}
Cflags: -I\${includedir}
Libs: -L\${libdir} -l${target} ${pc_external}
")
  install(FILES ${pc} DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT dev)

  # What the package config needs to load this component.
  set(config "set(_safecass_requires_${module} ${requires})\nset(_safecass_packages_${module} ${M_PACKAGES})\n")
  set_property(GLOBAL APPEND_STRING PROPERTY SAFECASS_MODULE_CONFIG "${config}")
  set_property(GLOBAL APPEND PROPERTY SAFECASS_INSTALLED_MODULES ${module})
  set_property(GLOBAL APPEND PROPERTY SAFECASS_DEBIAN_DEPENDS ${M_DEBIAN})
endfunction()

# Writes and installs safecassConfig.cmake, its version file, the Find modules it uses, and
# safecass.pc (every installed module).
function(safecass_install_package)
  cmake_parse_arguments(P "" "" "FIND_MODULES" ${ARGN})
  get_property(SAFECASS_KNOWN_MODULES GLOBAL PROPERTY SAFECASS_KNOWN_MODULES)
  get_property(SAFECASS_INSTALLED_MODULES GLOBAL PROPERTY SAFECASS_INSTALLED_MODULES)
  get_property(SAFECASS_MODULE_CONFIG GLOBAL PROPERTY SAFECASS_MODULE_CONFIG)
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/safecassConfig.cmake.in
    ${CMAKE_CURRENT_BINARY_DIR}/safecassConfig.cmake
    INSTALL_DESTINATION ${SAFECASS_CMAKE_INSTALL_DIR})
  write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/safecassConfigVersion.cmake
    COMPATIBILITY SameMinorVersion)
  install(FILES ${CMAKE_CURRENT_BINARY_DIR}/safecassConfig.cmake
                ${CMAKE_CURRENT_BINARY_DIR}/safecassConfigVersion.cmake
                ${P_FIND_MODULES}
          DESTINATION ${SAFECASS_CMAKE_INSTALL_DIR} COMPONENT dev)

  set(pc_requires)
  foreach(module IN LISTS SAFECASS_INSTALLED_MODULES)
    list(APPEND pc_requires safecass-${module})
  endforeach()
  list(JOIN pc_requires ", " pc_requires)
  set(pc "${CMAKE_CURRENT_BINARY_DIR}/pkgconfig/safecass.pc")
  file(GENERATE OUTPUT ${pc} CONTENT
"Name: safecass
Description: ${PROJECT_DESCRIPTION} (every installed module)
Version: ${PROJECT_VERSION}
Requires: ${pc_requires}
")
  install(FILES ${pc} DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT dev)
endfunction()
