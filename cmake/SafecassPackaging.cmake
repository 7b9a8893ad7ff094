# Debian packages with CPack (`make package`, docs/contributing.md "Packages"):
#
#   libsafecass-dev  the install component `dev`: static libraries, headers, CMake package config
#                    with its Find modules, pkg-config files, and examples/consumer as an example
#   safecass         the install component `tools`: the `safecass` command (its web pages are
#                    compiled into it), its man pages, the example specifications and scenarios, and
#                    start-icestorm (in libexec/safecass: the broker a multi-process system needs)
#   python3-safecass the install component `python`: `import safecass` for Debian's python3, with
#                    its pytest plugin (tools/python, docs/python.md)
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

if(TARGET safecass_python)
  list(APPEND SAFECASS_PACKAGE_COMPONENTS python)
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
# Found at run time: SPIN (and a C compiler) by `safecass verify`, SCRAM by `safecass analyze`.
set(CPACK_DEBIAN_TOOLS_PACKAGE_RECOMMENDS "spin, gcc, scram")
set(CPACK_COMPONENT_TOOLS_DESCRIPTION
  "the safecass command: validate, run, test, console, viewer, timeline\n"
  "Validates SAFECASS specifications, runs scenarios, and watches live systems in a terminal or a\n"
  "browser. Man pages: safecass(1) and safecass-<subcommand>(1).")

set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-safecass)
set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
set(CPACK_DEBIAN_PYTHON_PACKAGE_SHLIBDEPS ON)
# The module's own Python needs (its shared libraries are found by dpkg-shlibdeps); pandas and
# matplotlib are optional (to_pandas(), the plotting example).
set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS "python3 (>= 3.11), python3 (<< 3.12), python3-numpy")
set(CPACK_DEBIAN_PYTHON_PACKAGE_SUGGESTS "python3-pandas, python3-matplotlib, python3-pytest, safecass")
set(CPACK_COMPONENT_PYTHON_DESCRIPTION
  "SAFECASS from Python: import safecass\n"
  "Loads, runs, injects into, reads and verifies SAFECASS systems from Python 3; recordings as numpy\n"
  "arrays; a pytest plugin that runs scenario files as tests (docs/python.md).")

include(CPack)
