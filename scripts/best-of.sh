# Sourced by the perf scripts: best_of N OUT CMD... prints the best wall time (s) of N runs of
# CMD, whose standard output goes to OUT.
best_of() {
    local n=$1 out=$2 best="" t0 t1
    shift 2
    for _ in $(seq "$n"); do
        t0=$(date +%s.%N)
        "$@" > "$out"
        t1=$(date +%s.%N)
        best=$(python3 -c "print(min(float(x) for x in '$best $(python3 -c "print($t1 - $t0)")'.split()))")
    done
    echo "$best"
}
