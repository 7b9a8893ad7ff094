# Compiles one case of a source file and checks the outcome (cmake -P):
#   COMPILER, SOURCE, INCLUDE, CASE (the SAFECASS_CASE_* macro), EXPECT (compiles | fails),
#   MESSAGE (a text the compiler must print when EXPECT is fails).
set(ENV{LC_ALL} C)  # plain quotes in the compiler's messages
execute_process(
  COMMAND "${COMPILER}" -std=c++20 -fsyntax-only "-I${INCLUDE}" "-DSAFECASS_CASE_${CASE}" "${SOURCE}"
  RESULT_VARIABLE result
  OUTPUT_VARIABLE out
  ERROR_VARIABLE out)
if(EXPECT STREQUAL "compiles")
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "case ${CASE} of ${SOURCE} should compile, but:\n${out}")
  endif()
  message(STATUS "case ${CASE} compiles, as it should")
elseif(EXPECT STREQUAL "fails")
  if(result EQUAL 0)
    message(FATAL_ERROR "case ${CASE} of ${SOURCE} compiled, but it must be refused")
  endif()
  string(FIND "${out}" "${MESSAGE}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "case ${CASE} of ${SOURCE} failed, but not with '${MESSAGE}':\n${out}")
  endif()
  message(STATUS "case ${CASE} is refused: ${MESSAGE}")
else()
  message(FATAL_ERROR "EXPECT must be compiles or fails, not '${EXPECT}'")
endif()
