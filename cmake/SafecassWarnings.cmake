# Warnings every SAFECASS target is built with.
add_library(safecass_warnings INTERFACE)
target_compile_options(safecass_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
  -Wnon-virtual-dtor -Wold-style-cast -Woverloaded-virtual -Wimplicit-fallthrough)
