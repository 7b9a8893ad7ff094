#!/usr/bin/env bash
# Installs every Debian package SAFECASS needs to build, test and run its demo.
# Idempotent: when everything is present it checks with dpkg and returns in well under a second.
#   scripts/install-deps.sh [--bench-peers]
#     --bench-peers  also what only `make bench-peers` needs (the ROS diagnostics peers' headers)
set -euo pipefail
bench_peers=0
case "${1:-}" in
  '') ;;
  --bench-peers) bench_peers=1 ;;
  *) echo "install-deps: unknown argument '$1' (use --bench-peers or nothing)" >&2; exit 2 ;;
esac

packages=(
  build-essential cmake ninja-build pkg-config git
  libgtest-dev libgmock-dev libbenchmark-dev
  libexpected-dev libcli11-dev nlohmann-json3-dev libedit-dev libfmt-dev
  clang libclang-rt-14-dev
)
# `make lint` (scripts/lint): clang-format and clang-tidy 14; Universal Ctags for the function-length check.
packages+=(clang-format clang-tidy universal-ctags)
# ROS 2 over DDS (extensions/dds, examples/dds_robodoc, `make ros2-demo`): Eclipse Cyclone DDS's C
# library and its IDL compiler (idlc) and tools (ddsperf).
packages+=(cyclonedds-dev cyclonedds-tools libcycloneddsidl0)
# `safecass replay` of a ROS 2 bag (rosbag2's sqlite3 store) and of a ROS 1 bag (chunks compressed
# with bzip2 or LZ4).
packages+=(libsqlite3-dev libbz2-dev liblz4-dev)
# ROS 1 (extensions/ros1, examples/ros_robodoc, `make ros-demo`): roscore, roscpp, rosbag (the bag
# replay tests write their bags with rosbag's own writer), the messages,
# diagnostic_aggregator and rosdiagnostic; unshare/ip for the loopback-only test namespace.
packages+=(
  ros-core libroscpp-dev librosbag-dev libstd-msgs-dev libgeometry-msgs-dev libsensor-msgs-dev
  libdiagnostic-msgs-dev python3-diagnostic-msgs libdiagnostic-aggregator-tools rosdiagnostic
  python3-dateutil util-linux iproute2
)
# `safecass viewer` (tools/viewer): Boost.Beast; its page is TypeScript compiled with the npm packages
# of web/package.json (`make deps` runs `npm ci --prefix web`), and its browser test drives Debian's
# chromium. Debian's Node.js only when no `node` is installed.
packages+=(libboost-dev libboost-system-dev chromium)
command -v node >/dev/null 2>&1 || packages+=(nodejs npm)
# The middleware (middleware/, `safecass run --ice`, `safecass supervisor`, scripts/start-icestorm):
# ZeroC Ice 3.7 with slice2cpp, and IceBox hosting the IceStorm service; IceGrid for a replicated
# IceStorm (`scripts/start-icestorm --replicas`, `make cluster-demo`).
packages+=(zeroc-ice-compilers libzeroc-ice-dev zeroc-icebox libzeroc-icestorm3.7 zeroc-ice-utils zeroc-icegrid)
# Every bus message is signed (Ed25519, libsodium); `safecass trace` hashes the spec files with it.
packages+=(libsodium-dev)
# `safecass keys` makes the system's CA and the members' TLS certificates with OpenSSL's library.
packages+=(libssl-dev)
# `safecass verify` translates a system into Promela and model-checks it with SPIN (the verifier
# it generates is compiled with the system's gcc, from build-essential).
packages+=(spin)
# `safecass analyze` writes fault trees in the Open-PSA MEF and has SCRAM compute their minimal cut
# sets; it reads SCRAM's XML report with TinyXML-2.
packages+=(scram libtinyxml2-dev)

# `make bench-peers` (benchmarks/peers): diagnostic_updater for the ROS diagnostics peer; roscpp,
# diagnostic_aggregator, IceStorm and Boost (MSM, Statechart: header-only) are listed above.
if [ "$bench_peers" = 1 ]; then
  packages+=(libdiagnostic-updater-dev)
fi

# `import safecass` (tools/python, docs/python.md): pybind11 for Debian's python3, numpy for the
# recordings as arrays, pytest for its tests and plugin; pandas (to_pandas()) and matplotlib (the
# plotting example) are tested where present and installed here so that they are.
packages+=(pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-pandas python3-matplotlib)

# The trace report's browser test prints it to PDF with chromium and reads it back with pdftotext.
packages+=(poppler-utils)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
if ! "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}" >/dev/null; then
  "${sudo_cmd[@]}" apt-get update -q >/dev/null
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}" >/dev/null
fi
