#!/usr/bin/env bash
# SAFECASS from outside its tree: installed prefix, pkg-config, components, subproject, .deb packages.
# Usage: install_test.sh CASE   (environment from tests/install/CMakeLists.txt)
#   SAFECASS_SOURCE_DIR, SAFECASS_BINARY_DIR  the tree under test (already built)
#   SAFECASS_TEST_WORK                        where the fixtures put the prefix and the unpacked root
#   SAFECASS_CXX, SAFECASS_GENERATOR          the compiler and generator of the tree
#   SAFECASS_SANITIZER_FLAGS                  the tree's -fsanitize flags, for programs linking it
set -u
case_name=$1
src=$SAFECASS_SOURCE_DIR
bin=$SAFECASS_BINARY_DIR
work=$SAFECASS_TEST_WORK
prefix=$work/prefix
root=$work/root
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
mkdir -p "$work"

# Configures project $1 into $2 against the installation under $3; extra arguments go to cmake.
configure() {
  local source=$1 build=$2 at=$3
  shift 3
  cmake -S "$source" -B "$build" -G "$SAFECASS_GENERATOR" -DCMAKE_CXX_COMPILER="$SAFECASS_CXX" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_PREFIX_PATH="$at" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON \
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF \
    -DCMAKE_CXX_FLAGS="$SAFECASS_SANITIZER_FLAGS" -DCMAKE_EXE_LINKER_FLAGS="$SAFECASS_SANITIZER_FLAGS" "$@"
}

# The consumer in $1, configured against the installation under $2 (its usr or prefix), must take
# safecass from there and nothing from the source tree, then build and run.
consumer_against() {
  local consumer=$1 at=$2
  cp -r "$consumer" "$tmp/src" || fail "copy $consumer"
  configure "$tmp/src" "$tmp/build" "$at" >"$tmp/configure.log" 2>&1 || fail "configure: $(cat "$tmp/configure.log")"
  found=$(sed -n 's/^safecass_DIR:PATH=//p' "$tmp/build/CMakeCache.txt")
  [ "$found" = "$at/lib/cmake/safecass" ] || fail "safecass found in '$found', not in $at"
  # Every include directory of the build is the installation's or the system's.
  grep -o -e '-I *[^ "]*' -e '-isystem *[^ "]*' "$tmp/build/compile_commands.json" | sed 's/^-I *//; s/^-isystem *//' \
    | sort -u >"$tmp/includes"
  [ -s "$tmp/includes" ] || fail "no include directory in compile_commands.json"
  while read -r dir; do
    case $dir in
      "$at"/*) ;;
      "$src"/*) fail "include directory in the source tree: $dir" ;;
      /usr/*) ;;
      *) fail "unexpected include directory: $dir" ;;
    esac
  done <"$tmp/includes"
  grep -q "$at/include" "$tmp/includes" || fail "the installation's include directory is not used: $(cat "$tmp/includes")"
  cmake --build "$tmp/build" >"$tmp/build.log" 2>&1 || fail "build: $(tail -40 "$tmp/build.log")"
  "$tmp/build/gripper_consumer" "$tmp/src/gripper.json" >"$tmp/out" 2>&1 || fail "run: $(cat "$tmp/out")"
  grep -q "handlers ran as the specification says" "$tmp/out" || fail "output: $(cat "$tmp/out")"
  (cd "$tmp/build" && ctest --output-on-failure >"$tmp/ctest.log" 2>&1) || fail "consumer's ctest: $(cat "$tmp/ctest.log")"
}

# A small project that asks for `find_package(safecass $1)` and prints which safecass:: targets it got.
probe_components() {
  local want=$1 at=$2 dir=$3
  mkdir -p "$dir"
  cat >"$dir/CMakeLists.txt" <<EOF
cmake_minimum_required(VERSION 3.25)
project(probe LANGUAGES CXX)
find_package(safecass REQUIRED $want)
set(loaded)
foreach(m core filters json introspect spec record native middleware_token middleware ros_common ros1 dds runner)
  if(TARGET safecass::\${m})
    list(APPEND loaded \${m})
  endif()
endforeach()
message(STATUS "loaded: \${loaded}")
message(STATUS "Ice found: [\${Ice_FOUND}]")
EOF
  configure "$dir" "$dir/build" "$at" >"$dir/log" 2>&1
}

said() {  # CMake wraps its messages: look for text $1 in file $2 with lines joined
  tr -s ' \n' '  ' <"$2" | grep -q -- "$1"
}

installed_modules() {  # the modules of the installation under $1, from their export files
  ls "$1"/lib/cmake/safecass/ | sed -n 's/^safecass-\(.*\)-targets\.cmake$/\1/p' | sort
}

case $case_name in
  install.into_a_fresh_prefix)
    rm -rf "$prefix"
    cmake --install "$bin" --prefix "$prefix" --component dev >"$tmp/log" 2>&1 || fail "install: $(cat "$tmp/log")"
    for f in lib/cmake/safecass/safecassConfig.cmake lib/cmake/safecass/safecassConfigVersion.cmake \
             lib/cmake/safecass/FindIce.cmake lib/cmake/safecass/FindSodium.cmake \
             include/safecass/core/coordinator.hpp include/safecass/spec/load.hpp include/safecass/record/recorder.hpp \
             include/safecass/native/runtime.hpp include/safecass/runner/scenario_runner.hpp \
             lib/libsafecass_core.a lib/pkgconfig/safecass.pc lib/pkgconfig/safecass-core.pc; do
      [ -f "$prefix/$f" ] || fail "not installed: $f"
    done
    for m in core filters spec record native runner; do
      installed_modules "$prefix" | grep -qx "$m" || fail "module $m not exported"
    done
    [ -e "$prefix/bin/safecass" ] && fail "the dev component installed the command"
    echo "installed modules: $(installed_modules "$prefix" | tr '\n' ' ')"
    ;;
  install.consumer_builds_and_runs_against_the_prefix_only)
    consumer_against "$src/examples/consumer" "$prefix"
    ;;
  install.pkg_config_consumer_builds_and_runs)
    export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
    flags=$(pkg-config --cflags --libs safecass-spec safecass-native) || fail "pkg-config: $flags"
    case " $flags " in *" -I$prefix/lib/pkgconfig/../../include "*|*" -I$prefix/include "*) ;;
      *) fail "flags do not name the prefix's headers: $flags" ;; esac
    # shellcheck disable=SC2086
    "$SAFECASS_CXX" -std=c++20 $SAFECASS_SANITIZER_FLAGS "$src/examples/consumer/main.cpp" -o "$tmp/consumer" $flags \
      >"$tmp/build.log" 2>&1 || fail "build with '$flags': $(tail -40 "$tmp/build.log")"
    "$tmp/consumer" "$src/examples/consumer/gripper.json" >"$tmp/out" 2>&1 || fail "run: $(cat "$tmp/out")"
    grep -q "handlers ran as the specification says" "$tmp/out" || fail "output: $(cat "$tmp/out")"
    # Every module has its .pc file, and the umbrella asks for all of them.
    for m in $(installed_modules "$prefix"); do
      pkg-config --exists "safecass-$m" || fail "no pkg-config file for $m"
    done
    pkg-config --exists safecass || fail "no safecass.pc"
    ;;
  install.components_load_only_the_modules_they_need)
    probe_components "COMPONENTS core" "$prefix" "$tmp/core" || fail "core: $(cat "$tmp/core/log")"
    grep -q -- "-- loaded: core$" "$tmp/core/log" || fail "core: $(grep loaded "$tmp/core/log")"
    grep -q -- "-- Ice found: \[\]" "$tmp/core/log" || fail "core needed Ice: $(grep Ice "$tmp/core/log")"
    probe_components "COMPONENTS spec" "$prefix" "$tmp/spec" || fail "spec: $(cat "$tmp/spec/log")"
    grep -q -- "-- loaded: core;filters;json;spec$" "$tmp/spec/log" || fail "spec: $(grep loaded "$tmp/spec/log")"
    if installed_modules "$prefix" | grep -qx middleware; then
      probe_components "COMPONENTS middleware" "$prefix" "$tmp/mw" || fail "middleware: $(cat "$tmp/mw/log")"
      grep -q -- "-- loaded: core;filters;json;introspect;spec;middleware_token;middleware$" "$tmp/mw/log" \
        || fail "middleware: $(grep loaded "$tmp/mw/log")"
      grep -q -- "-- Ice found: \[\(1\|TRUE\|ON\)\]" "$tmp/mw/log" || fail "middleware without Ice: $(grep Ice "$tmp/mw/log")"
    fi
    # Without COMPONENTS: every installed module.
    probe_components "" "$prefix" "$tmp/all" || fail "all: $(cat "$tmp/all/log")"
    loaded=$(sed -n 's/^-- loaded: //p' "$tmp/all/log" | tr ';' '\n' | sort)
    [ "$loaded" = "$(installed_modules "$prefix")" ] || fail "all: loaded $loaded"
    ;;
  install.unknown_or_unbuilt_component_is_a_clear_error)
    probe_components "COMPONENTS core nonsense" "$prefix" "$tmp/bad" && fail "an unknown component was accepted"
    said "safecass: unknown component 'nonsense' (the components are: core, filters," "$tmp/bad/log" \
      || fail "message: $(cat "$tmp/bad/log")"
    # A module this project has but that was not built (here: runner, taken out of a copy of the
    # installed config) is named as such.
    cp -r "$prefix" "$tmp/copy"
    sed -i 's/^set(_safecass_installed_modules \(.*\)runner)$/set(_safecass_installed_modules \1)/' \
      "$tmp/copy/lib/cmake/safecass/safecassConfig.cmake"
    grep -q '^set(_safecass_installed_modules .*runner' "$tmp/copy/lib/cmake/safecass/safecassConfig.cmake" \
      && fail "could not take runner out of the config copy"
    probe_components "COMPONENTS runner" "$tmp/copy" "$tmp/unbuilt" && fail "a module not built was accepted"
    said "safecass: component 'runner' is not part of this installation (it was not built)" "$tmp/unbuilt/log" \
      || fail "message: $(cat "$tmp/unbuilt/log")"
    # OPTIONAL_COMPONENTS: a missing module is not an error.
    probe_components "COMPONENTS core OPTIONAL_COMPONENTS runner" "$tmp/copy" "$tmp/optional" \
      || fail "optional: $(cat "$tmp/optional/log")"
    ;;
  install.subproject_gets_libraries_without_tests_tools_or_benchmarks)
    mkdir -p "$tmp/parent"
    cat >"$tmp/parent/CMakeLists.txt" <<EOF
cmake_minimum_required(VERSION 3.25)
project(parent LANGUAGES CXX)
enable_testing()
add_subdirectory("$src" safecass)
foreach(t core filters spec record native)
  if(NOT TARGET safecass::\${t})
    message(FATAL_ERROR "no safecass::\${t}")
  endif()
endforeach()
foreach(t safecass safecass_runner safecass_bench custom_filter_example)
  if(TARGET \${t})
    message(FATAL_ERROR "the subproject built \${t}")
  endif()
endforeach()
add_executable(app "$src/examples/consumer/main.cpp")
target_link_libraries(app PRIVATE safecass::spec safecass::native)
EOF
    cmake -S "$tmp/parent" -B "$tmp/build" -G "$SAFECASS_GENERATOR" -DCMAKE_CXX_COMPILER="$SAFECASS_CXX" \
      >"$tmp/log" 2>&1 || fail "configure: $(tail -40 "$tmp/log")"
    ctest --test-dir "$tmp/build" -N >"$tmp/tests" 2>&1
    grep -q "Total Tests: 0" "$tmp/tests" || fail "tests came with the subproject: $(tail -5 "$tmp/tests")"
    cmake --install "$tmp/build" --prefix "$tmp/installed" >"$tmp/install.log" 2>&1 || fail "install: $(cat "$tmp/install.log")"
    [ -e "$tmp/installed" ] && fail "the subproject installed files: $(find "$tmp/installed" | head)"
    ;;
  package.debs_build_and_unpack)
    rm -rf "$work/debs" "$root"
    cpack --config "$bin/CPackConfig.cmake" -B "$work/debs" >"$tmp/log" 2>&1 || fail "cpack: $(tail -40 "$tmp/log")"
    ls "$work"/debs/libsafecass-dev_*.deb "$work"/debs/safecass_*.deb >/dev/null || fail "packages: $(ls "$work/debs")"
    for deb in "$work"/debs/*.deb; do
      dpkg-deb -x "$deb" "$root" || fail "dpkg-deb -x $deb"
      echo "$(basename "$deb"): $(du -k "$deb" | cut -f1) KiB"
    done
    ;;
  package.unpacked_safecass_validates_an_example)
    safecass=$root/usr/bin/safecass
    examples=$root/usr/share/doc/safecass/examples
    "$safecass" --version | grep -q '^safecass [0-9]' || fail "--version: $("$safecass" --version)"
    "$safecass" validate "$examples/robodoc/robodoc.json" >"$tmp/out" 2>&1 || fail "validate robodoc: $(cat "$tmp/out")"
    "$safecass" validate "$examples/force_sensor/force_sensor.json" >"$tmp/out" 2>&1 || fail "validate force_sensor: $(cat "$tmp/out")"
    # It really checks: a broken copy is reported where it is broken.
    sed 's/"threshold": 30.0/"threshold": "high"/' "$examples/force_sensor/force_sensor.json" >"$tmp/broken.json"
    "$safecass" validate "$tmp/broken.json" >"$tmp/out" 2>&1; code=$?
    [ $code = 1 ] || fail "broken spec: exit $code: $(cat "$tmp/out")"
    grep -q "broken.json:[0-9]*:[0-9]*: error: .*threshold" "$tmp/out" || fail "broken spec: $(cat "$tmp/out")"
    ;;
  package.man_pages_cover_every_subcommand)
    safecass=$root/usr/bin/safecass
    man1=$root/usr/share/man/man1
    subs=$("$safecass" --help | sed -n '/^Subcommands:/,/^$/s/^  \([a-z][a-z-]*\).*/\1/p')
    [ -n "$subs" ] || fail "no subcommand in --help"
    [ -f "$man1/safecass.1.gz" ] || fail "no safecass.1.gz"
    for sub in $subs; do
      page=$man1/safecass-$sub.1.gz
      [ -f "$page" ] || fail "no man page for $sub"
      zcat "$page" | grep -q "^\.SH NAME" || fail "$sub: no NAME section"
      zcat "$page" | grep -q "^safecass\\\\-$sub \\\\- ." || fail "$sub: no summary: $(zcat "$page" | head -5)"
      zcat "$man1/safecass.1.gz" | grep -q "fBsafecass\\\\-$sub\\\\fR(1)" || fail "safecass(1) does not refer to $sub"
      if command -v man >/dev/null; then
        MANWIDTH=100 man -l "$page" 2>"$tmp/err" | grep -q -- "--help" || fail "$sub: man cannot render it: $(cat "$tmp/err")"
        [ -s "$tmp/err" ] && fail "$sub: man warns: $(cat "$tmp/err")"
      fi
    done
    echo "man pages: safecass $(echo $subs)"
    ;;
  package.consumer_builds_against_the_unpacked_dev_package)
    consumer_against "$root/usr/share/doc/libsafecass-dev/examples/consumer" "$root/usr"
    ;;
  package.debs_declare_their_dependencies)
    dev=$(ls "$work"/debs/libsafecass-dev_*.deb)
    tools=$(ls "$work"/debs/safecass_*.deb)
    [ "$(dpkg-deb -f "$dev" Package)" = libsafecass-dev ] || fail "dev package name"
    dpkg-deb -f "$dev" Depends | grep -q "libexpected-dev" || fail "dev Depends: $(dpkg-deb -f "$dev" Depends)"
    if [ -f "$root/usr/lib/libsafecass_middleware.a" ]; then
      dpkg-deb -f "$dev" Depends | grep -q "libzeroc-ice-dev" || fail "dev Depends misses Ice: $(dpkg-deb -f "$dev" Depends)"
    fi
    dpkg-deb -f "$tools" Depends | grep -q "libc6" || fail "tools Depends (shlibdeps): $(dpkg-deb -f "$tools" Depends)"
    dpkg-deb -c "$dev" | grep -q "/usr/bin/" && fail "the -dev package holds a command"
    dpkg-deb -c "$tools" | grep -q "\.a$" && fail "the command's package holds a library"
    ;;
  package.unpacked_python3_safecass_imports_and_runs_robodoc)
    py=$(ls "$work"/debs/python3-safecass_*.deb)
    dpkg-deb -f "$py" Depends | grep -q "python3-numpy" || fail "python3-safecass Depends: $(dpkg-deb -f "$py" Depends)"
    dpkg-deb -f "$py" Depends | grep -q "libc6" || fail "python3-safecass Depends (shlibdeps): $(dpkg-deb -f "$py" Depends)"
    [ -x "$root/usr/libexec/safecass/start-icestorm" ] || fail "no start-icestorm in the tools package"
    examples=$root/usr/share/doc/safecass/examples
    PYTHONPATH=$root/usr/lib/python3/dist-packages /usr/bin/python3 - "$examples/robodoc/robodoc.json" >"$tmp/out" 2>&1 <<'PY' || fail "python3-safecass: $(cat "$tmp/out")"
import importlib.metadata, sys
import safecass
robot = safecass.System(sys.argv[1])
robot.generate("EVT_FORCE_ERROR", "JR3.s_A")
assert robot.state("SERVO") == "Error", robot.levels()
plugins = [e.value for e in importlib.metadata.entry_points(group="pytest11")]
assert "safecass.pytest_plugin" in plugins, plugins
print("python3-safecass", safecass.__version__, safecass.__file__)
PY
    grep -q "^python3-safecass .*/usr/lib/python3/dist-packages/safecass/__init__.py" "$tmp/out" || fail "imported from elsewhere: $(cat "$tmp/out")"
    ;;
  *) fail "unknown case $case_name" ;;
esac
echo "ok: $case_name"
