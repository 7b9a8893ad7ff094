# Warnings every SAFECASS target is built with.
add_library(safecass_warnings INTERFACE)
target_compile_options(safecass_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
  -Wnon-virtual-dtor -Wold-style-cast -Woverloaded-virtual -Wimplicit-fallthrough)
# In a unity source (CMAKE_UNITY_BUILD, the presets' builds) gcc takes each included file's
# anonymous namespace for a header's and warns when a class of that file uses it; compiled alone
# the same file gets no such warning.
target_compile_options(safecass_warnings INTERFACE
  $<$<AND:$<CXX_COMPILER_ID:GNU>,$<BOOL:$<TARGET_PROPERTY:UNITY_BUILD>>>:-Wno-subobject-linkage>)
