# Debian packages with CPack (`make package`, docs/contributing.md "Packages"):
#
#   libsafecass-dev  the install component `dev`: static libraries, headers, CMake package config
#                    with its Find modules, pkg-config files, and examples/consumer as an example
#   safecass         the install component `tools`: the `safecass` command (its web pages are
#                    compiled into it), its man pages, and the example specifications and scenarios
#
# Both install under /usr. The Debian packages the libraries need come from the
# safecass_install_module() lines; those of the command are found by dpkg-shlibdeps.

install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/consumer/
        DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/doc/libsafecass-dev/examples/consumer COMPONENT dev)
set(SAFECASS_PACKAGE_COMPONENTS dev)
if(TARGET safecass)
  list(APPEND SAFECASS_PACKAGE_COMPONENTS tools)
  foreach(example force_sensor robodoc)
    install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/${example}
            DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/doc/safecass/examples COMPONENT tools
            FILES_MATCHING PATTERN "*.json")
  endforeach()
endif()

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME safecass)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
set(CPACK_PACKAGE_CONTACT "SAFECASS maintainers <safecass@invalid>")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_PACKAGE_DIRECTORY ${PROJECT_BINARY_DIR}/packages)
set(CPACK_COMPONENTS_ALL ${SAFECASS_PACKAGE_COMPONENTS})
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_STRIP_FILES ON)  # the command; static libraries keep their symbols

set(CPACK_DEBIAN_DEV_PACKAGE_NAME libsafecass-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_COMPONENT_DEV_DESCRIPTION
  "SAFECASS libraries, headers and CMake package config\n"
  "Static libraries of every SAFECASS module (safecass::core, ::filters, ::spec, ::record, ::native,\n"
  "::middleware, ::ros_common, ::ros1, ::dds, ::runner as built), their headers, find_package(safecass) and pkg-config files.")
get_property(SAFECASS_DEBIAN_DEPENDS GLOBAL PROPERTY SAFECASS_DEBIAN_DEPENDS)
list(REMOVE_DUPLICATES SAFECASS_DEBIAN_DEPENDS)
list(JOIN SAFECASS_DEBIAN_DEPENDS ", " CPACK_DEBIAN_DEV_PACKAGE_DEPENDS)

set(CPACK_DEBIAN_TOOLS_PACKAGE_NAME safecass)
set(CPACK_DEBIAN_TOOLS_PACKAGE_SECTION devel)
set(CPACK_DEBIAN_TOOLS_PACKAGE_SHLIBDEPS ON)
set(CPACK_COMPONENT_TOOLS_DESCRIPTION
  "the safecass command: validate, run, test, console, viewer, timeline\n"
  "Validates SAFECASS specifications, runs scenarios, and watches live systems in a terminal or a\n"
  "browser. Man pages: safecass(1) and safecass-<subcommand>(1).")

include(CPack)
