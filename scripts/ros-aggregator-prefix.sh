#!/usr/bin/env bash
# Builds the small ament-index prefix that Debian's diagnostic_aggregator node needs to find its
# analyzer plugins (Debian ships the library but no plugin description or package.xml).
#
# Usage: scripts/ros-aggregator-prefix.sh PREFIX_DIR
# Then:  AMENT_PREFIX_PATH=PREFIX_DIR /usr/lib/diagnostic_aggregator/aggregator_node
# Everything written is generated here; the system library is only linked to, never copied.
set -euo pipefail

prefix=${1:?usage: $0 PREFIX_DIR}
multiarch=$(gcc -print-multiarch 2>/dev/null || echo x86_64-linux-gnu)
system_lib=$(ls /usr/lib/"$multiarch"/libdiagnostic_aggregator.so.* 2>/dev/null | head -1 || true)
if [ -z "$system_lib" ]; then
  echo "ros-aggregator-prefix: libdiagnostic_aggregator is not installed (apt-get install libdiagnostic-aggregator-tools)" >&2
  exit 1
fi

mkdir -p "$prefix/lib" "$prefix/share/diagnostic_aggregator" \
         "$prefix/share/ament_index/resource_index/packages" \
         "$prefix/share/ament_index/resource_index/diagnostic_aggregator__pluginlib__plugin"
ln -sfn "$system_lib" "$prefix/lib/libdiagnostic_aggregator.so"
: >"$prefix/share/ament_index/resource_index/packages/diagnostic_aggregator"
echo "share/diagnostic_aggregator/analyzer_plugins.xml" \
  >"$prefix/share/ament_index/resource_index/diagnostic_aggregator__pluginlib__plugin/diagnostic_aggregator"

cat >"$prefix/share/diagnostic_aggregator/package.xml" <<'XML'
<?xml version="1.0"?>
<package format="2">
  <name>diagnostic_aggregator</name>
  <version>0.0.0</version>
  <description>Index entry generated for the system diagnostic_aggregator library.</description>
  <maintainer email="nobody@localhost">generated</maintainer>
  <license>BSD</license>
  <export>
    <diagnostic_aggregator plugin="${prefix}/analyzer_plugins.xml"/>
  </export>
</package>
XML

analyzer() {
  printf '  <class name="diagnostic_aggregator/%s" type="diagnostic_aggregator::%s" base_class_type="diagnostic_aggregator::Analyzer">\n    <description>%s</description>\n  </class>\n' "$1" "$1" "$2"
}
{
  echo '<library path="diagnostic_aggregator">'
  analyzer GenericAnalyzer "Groups statuses by name (path, startswith, contains, name, expected)."
  analyzer AnalyzerGroup "A group of analyzers."
  analyzer DiscardAnalyzer "Drops the statuses it matches."
  analyzer IgnoreAnalyzer "Ignores a namespace."
  echo '</library>'
} >"$prefix/share/diagnostic_aggregator/analyzer_plugins.xml"
echo "$prefix"
