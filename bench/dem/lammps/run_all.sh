#!/usr/bin/env bash
# Runs the LAMMPS peer bench and seep's DEM bench in the same session, twice each.
# usage: bash run_all.sh [OUT=build/lammps_bench] ["1 10" = RX values]   (needs: apt-get install -y lammps)
# The seep bench is taken from BUILD (default build/check, what scripts/check.sh builds); paths are
# relative to the repository.
# Before each run it prints `uptime` and the top 3 processes; during each run a sampler writes the
# processes using > 20% CPU every 2 s to OUT/busy.*.txt (anything but lmp / seep_dem_bench there
# means the run shared the machine). QUIET_WAIT=600 waits up to 600 s for a quiet machine before each run.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../../.." && pwd)  # the repository
BED=$ROOT/bench/settled_bed_9900.txt
SEEP=$ROOT/${BUILD:-build/check}/bench/dem/seep_dem_bench
OUT=${1:-$ROOT/build/lammps_bench}
RXS=${2:-1 10}
mkdir -p "$OUT"
python3 "$HERE/bed_to_lammps.py" "$BED" "$OUT/bed_9900.data"
echo "seep binary: $(stat -c '%y' "$SEEP") md5 $(md5sum < "$SEEP" | cut -c1-12); lmp: $(lmp -h | sed -n 's/^Large-scale[^-]*- //p')"
others() {  # processes other than ours above 20% CPU over 0.5 s
  top -bn2 -d0.5 -w512 | awk '/^top -/{f++} f==2 && $1~/^[0-9]+$/ && $9>20 {print $12}' |
    { grep -v -E "^(lmp|seep_dem_bench|mpirun|orted|top)$" || true; } | tr '\n' ' '
}
QUIET_WAIT=${QUIET_WAIT:-0}   # seconds to wait (at most) for 3 quiet samples in a row before a run
waitquiet() {
  local t0=$SECONDS q=0
  while [ $((SECONDS - t0)) -lt "$QUIET_WAIT" ] && [ $q -lt 3 ]; do
    if [ -z "$(others)" ]; then q=$((q + 1)); else q=0; sleep 2; fi
  done
}
load() { waitquiet; echo "== $1: $(uptime)"; ps -eo pcpu,pid,comm --sort=-pcpu | sed -n 2,4p; }
sampler() {  # file: every 2 s, processes above 20% CPU (instantaneous, from top)
  while :; do
    top -bn2 -d0.5 -w512 | awk '/^top -/{f++} f==2 && $1~/^[0-9]+$/ && $9>20 {print strftime("%T"), $9, $12}' >> "$1"
    sleep 1.5
  done
}
busy() {  # tag: summary of other processes seen by the sampler
  local f="$OUT/busy.$1.txt"
  local other; other=$( { grep -v -E " (lmp|seep_dem_bench|mpirun|orted|top)$" "$f" 2>/dev/null || true; } | awk "{print \$3}" | sort | uniq -c | tr "\n" " ")
  echo "   other busy processes during run: ${other:-none}"
}
lrun() {  # np rx nsteps tag
  load "lammps np=$1 RX=$2 $4"
  sampler "$OUT/busy.np$1.rx$2.$4.txt" & local sp=$!
  mpirun --allow-run-as-root -np "$1" lmp -log "$OUT/log.np$1.rx$2.$4" -screen none \
    -var DATA "$OUT/bed_9900.data" -var RX "$2" -var NSTEPS "$3" -in "$HERE/in.bench2d"
  kill "$sp"; wait "$sp" 2>/dev/null || true
  grep "^Loop time" "$OUT/log.np$1.rx$2.$4" | tail -2 | head -1
  busy "np$1.rx$2.$4"
}
for rx in $RXS; do
  if [ "$rx" = 1 ]; then n=10000; else n=2000; fi
  for rep in a b; do
    lrun 1 $rx $n $rep
    lrun 2 $rx $n $rep
    load "seep rx=$rx $rep"
    sampler "$OUT/busy.seep.rx$rx.$rep.txt" & sp=$!
    "$SEEP" "$BED" $rx 2000 | tee "$OUT/seep.rx$rx.$rep.txt"
    kill "$sp"; wait "$sp" 2>/dev/null || true
    busy "seep.rx$rx.$rep"
  done
done
