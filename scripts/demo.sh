#!/usr/bin/env bash
# README command 1: install, build, start seepd on loopback with its database in ./seep-data,
# submit the main job (a staged hydraulic-fracturing test) with the seep CLI, show its progress,
# result and particle picture, stop seepd cleanly.
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DSEEP_BUILD_TESTS=OFF \
  -DSEEP_BUILD_BENCH=OFF >/dev/null
cmake --build build/release --target seepd seep

data_dir=seep-data
mkdir -p "$data_dir"
rm -f "$data_dir/port"
./build/release/service/seepd --listen 127.0.0.1:0 --data-dir "$data_dir" \
  --port-file "$data_dir/port" 2>>"$data_dir/seepd.console.log" &
seepd_pid=$!
trap 'kill "$seepd_pid" 2>/dev/null || true' EXIT
for _ in $(seq 100); do [ -s "$data_dir/port" ] && break; sleep 0.1; done
[ -s "$data_dir/port" ] || { echo "demo: seepd did not start (see $data_dir/seepd.log)" >&2; exit 1; }
export SEEP_SERVER="127.0.0.1:$(cat "$data_dir/port")"
echo "== seepd is serving on $SEEP_SERVER (database $data_dir/seep.db)"

seep=./build/release/client/seep
"$seep" health
# The main job: a coupled laboratory test in stages (confine until the platens hold, inject until
# breakdown, shut in), about half a minute.
scene=examples/anisotropic_fracturing.textproto
echo "== submitting $scene"
job=$("$seep" --json submit "$scene" | python3 -c 'import json, sys; print(json.load(sys.stdin)["id"])')
"$seep" watch "$job"
"$seep" show "$job"
picture="$data_dir/$job-particles.svg"
"$seep" plot "$job" --what particles -o "$picture"
echo "== the particle picture (bonds broken by the fracture in red): $picture"
echo "== jobs on this server"
"$seep" list

kill -TERM "$seepd_pid"
wait "$seepd_pid"
trap - EXIT
echo "== seepd stopped cleanly; its log is $data_dir/seepd.log"
