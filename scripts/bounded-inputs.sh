#!/usr/bin/env bash
# The refusal of oversize inputs, measured (issue 59, Deliver 2): for every file option of the
# command line (--probe, --config, --overlay, --sample, a sample map's height_map CSV and NPY,
# reconstruct --fm and --am, fit --data, and the store files a --resume reads: a sweep's ledger, rows and
# partial rows, a study's ledger and records), the wall time and peak RSS
# (`/usr/bin/time -f '%e %M'`) of the refusal of /dev/zero and of a 2 GiB sparse file. Prints
# the table and fails if any refusal takes 1 s or more, or 100 MB or more, or is not a refusal
# (exit code 2). Outside the test command: timings are not asserted in tests (a loaded machine
# would make them race); the refusals themselves are tested in
# crates/afmdyn-cli/tests/bounded_inputs.rs.
# Usage: bash scripts/bounded-inputs.sh          (about a minute, after the release build)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q -p afmdyn-cli
A=$PWD/target/release/afmdyn
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
PROBE=examples/probe-point-mass-dmt.toml
fail=0
printf '%-34s %-12s %8s %10s %5s\n' "input" "file" "wall (s)" "peak (MB)" "exit"
# measure NAME KIND COMMAND...: one refusal, timed
measure() {
  local name=$1 kind=$2; shift 2
  local code=0
  /usr/bin/time -f "%e %M" -o "$tmp/time" "$@" > /dev/null 2> "$tmp/err" || code=$?
  # /usr/bin/time writes its line last in its own file
  read -r secs kb < <(tail -n 1 "$tmp/time")
  local mb; mb=$(python3 -c "print(f'{$kb / 1000:.1f}')")
  printf '%-34s %-12s %8s %10s %5s\n' "$name" "$kind" "$secs" "$mb" "$code"
  if [ "$code" != 2 ]; then
    echo "  not refused (exit $code): $(head -c 300 "$tmp/err")"
    fail=1
  elif ! python3 -c "import sys; sys.exit(0 if $secs < 1.0 and $kb < 100000 else 1)"; then
    echo "  too slow or too large: $(head -c 300 "$tmp/err")"
    fail=1
  fi
}
# each FILE-MAKER: /dev/zero (a symbolic link, so that a height map keeps its extension) and a
# 2 GiB sparse file, at the path $2
zero() { rm -f "$1"; ln -s /dev/zero "$1"; }
sparse() { rm -f "$1"; truncate -s 2G "$1"; }
for make in zero sparse; do
  f=$tmp/input
  $make "$f.toml"
  measure "modes --probe" "$make" $A modes --probe "$f.toml"
  measure "modes --config" "$make" $A modes --config "$f.toml"
  measure "units --config" "$make" $A units --config "$f.toml"
  measure "image --sample" "$make" $A image --probe $PROBE --sample "$f.toml" --setpoint 0.7
  $make "$f.csv"
  measure "continue --overlay" "$make" $A continue --from 3 --to 2.9 --overlay "$f.csv" --out "$tmp/o"
  measure "reconstruct --fm (CSV)" "$make" $A reconstruct --fm "$f.csv" --out "$tmp/o"
  measure "fit --data" "$make" $A fit --probe examples/probe-fit-hertz.toml --data "$f.csv" --out "$tmp/o"
  $make "$f.json"
  measure "reconstruct --fm (JSON)" "$make" $A reconstruct --fm "$f.json" --out "$tmp/o"
  measure "reconstruct --am" "$make" $A reconstruct --am "$f.json" --out "$tmp/o"
  for ext in csv npy; do
    $make "$tmp/h.$ext"
    printf 'size = [1e-6, 0]\nheight_map = "h.%s"\n' "$ext" > "$tmp/map-$ext.toml"
    measure "image --sample: height_map .$ext" "$make" $A image --probe $PROBE \
      --sample "$tmp/map-$ext.toml" --setpoint 0.7
  done
done
# the stores a --resume reads: made once by a small run, then each file replaced in turn
sweep=(bifurcation --from 2.4 --to 2.9 --steps 2 --starts 0 --max-periods 100 --threads 1
  --out "$tmp/sweep")
chart=(chart --x-steps 2 --y-steps 1 --starts 1 --tile 1 --lyapunov-periods 20
  --out "$tmp/chart")
$A "${sweep[@]}" > /dev/null
$A "${chart[@]}" > /dev/null
for spec in "sweep .bifurcation.run.json" "sweep bifurcation.csv" \
  "sweep .bifurcation.partial.csv" "chart .chart.run.json" "chart .chart.tiles.jsonl"; do
  read -r store file <<< "$spec"
  path=$tmp/$store/$file
  rm -f "$tmp/saved"
  [ -e "$path" ] && cp "$path" "$tmp/saved"
  for make in zero sparse; do
    $make "$path"
    if [ "$store" = sweep ]; then
      measure "--resume: $file" "$make" $A "${sweep[@]}" --resume
    else
      measure "--resume: $file" "$make" $A "${chart[@]}" --resume
    fi
  done
  rm -f "$path"
  [ -e "$tmp/saved" ] && mv "$tmp/saved" "$path"
done
if [ "$fail" != 0 ]; then
  echo "FAIL: a refusal took 1 s or more, or 100 MB or more, or was not a refusal"
  exit 1
fi
echo "every refusal under 1 s and 100 MB"
