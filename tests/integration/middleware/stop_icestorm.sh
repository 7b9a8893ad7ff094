#!/usr/bin/env bash
# Stops the IceStorm of the ctest fixture by the PID scripts/start-icestorm wrote (--env FILE).
set -u
env_file="$1"
[ -f "$env_file" ] || { echo "stop_icestorm: no $env_file: nothing to stop"; exit 0; }
pid=$(sed -n 's/^ICESTORM_PID=//p' "$env_file")
[ -n "$pid" ] || { echo "stop_icestorm: no PID in $env_file"; exit 1; }
kill "$pid" 2>/dev/null || { echo "stop_icestorm: PID $pid already gone"; exit 0; }
for _ in $(seq 1 100); do
  kill -0 "$pid" 2>/dev/null || { echo "stop_icestorm: stopped PID $pid"; exit 0; }
  sleep 0.05
done
kill -9 "$pid" 2>/dev/null
echo "stop_icestorm: killed PID $pid"
