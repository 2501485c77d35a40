#!/usr/bin/env bash
# Run every cargo-fuzz target for a bounded time, one after another, and print a summary line per
# target: executions, exec/s, corpus size, coverage, crashes.
#
#   scripts/fuzz.sh [SECONDS_PER_TARGET]      (default 600)
#
# Environment:
#   FUZZ_TARGETS   space-separated targets to run (default: every target in fuzz/Cargo.toml)
#   FUZZ_TIMEOUT   libFuzzer -timeout: seconds one input may take before it counts as a crash (30)
#   FUZZ_ARGS      extra libFuzzer arguments, e.g. "-max_len=8192"
#
# Needs the nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz`). Each target fuzzes
# `fuzz/corpus/<target>/` (the working corpus, git-ignored; new inputs go there) and reads the
# committed seeds in `fuzz/seeds/<target>/` and past crashes in `fuzz/regressions/<target>/`. Crash inputs land in `fuzz/artifacts/<target>/`;
# the full libFuzzer log of each run is `fuzz/target/fuzz-logs/<target>.log`. Exits non-zero if
# any target crashed. See fuzz/README.md.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

secs="${1:-600}"
if ! [[ "$secs" =~ ^[0-9]+$ ]] || [ "$secs" -eq 0 ]; then
    echo "usage: $0 [SECONDS_PER_TARGET]   (a whole number > 0, default 600)" >&2
    exit 2
fi
timeout_s="${FUZZ_TIMEOUT:-30}"
read -r -a extra <<<"${FUZZ_ARGS:-}"

cd fuzz
if [ -n "${FUZZ_TARGETS:-}" ]; then
    read -r -a targets <<<"$FUZZ_TARGETS"
else
    mapfile -t targets < <(cargo +nightly fuzz list)
fi
logs=target/fuzz-logs
mkdir -p "$logs"

# Build everything once, so the time limit is spent fuzzing.
for t in "${targets[@]}"; do
    cargo +nightly fuzz build "$t"
done

count_artifacts() {
    find "artifacts/$1" -maxdepth 1 -type f \
        \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) \
        2>/dev/null | wc -l
}

summary=()
failed=0
for t in "${targets[@]}"; do
    corpus="corpus/$t"
    mkdir -p "$corpus" "artifacts/$t"
    dirs=("$corpus")
    [ -d "seeds/$t" ] && dirs+=("seeds/$t")
    [ -d "regressions/$t" ] && dirs+=("regressions/$t")
    before=$(count_artifacts "$t")
    log="$logs/$t.log"
    echo "==> $t: ${secs}s (log: fuzz/$log)"
    start=$(date +%s)
    set +e
    cargo +nightly fuzz run "$t" "${dirs[@]}" -- \
        -max_total_time="$secs" -timeout="$timeout_s" -print_final_stats=1 \
        "${extra[@]}" >"$log" 2>&1
    rc=$?
    set -e
    elapsed=$(($(date +%s) - start))
    after=$(count_artifacts "$t")
    crashes=$((after - before))
    if [ "$rc" -ne 0 ] && [ "$crashes" -eq 0 ]; then
        crashes=1 # a failure without an artifact (build error, sanitizer abort): see the log
    fi
    [ "$crashes" -gt 0 ] && failed=1

    final_stat() { grep -o "^stat::$1: *[0-9]*" "$log" | tail -1 | awk '{print $2}'; }
    execs=$(final_stat number_of_executed_units)
    [ -n "$execs" ] || execs=$(grep -o 'Done [0-9]* runs' "$log" | tail -1 | awk '{print $2}')
    rate=$(final_stat average_exec_per_sec)
    last=$(grep -E '^#[0-9]+' "$log" | grep -E 'cov: ' | tail -1 || true)
    cov=$(grep -o 'cov: [0-9]*' <<<"$last" | awk '{print $2}')
    ft=$(grep -o 'ft: [0-9]*' <<<"$last" | awk '{print $2}')
    # libFuzzer's corpus (units kept in memory) and the files in the corpus folder (which also
    # keeps inputs later superseded; `cargo fuzz cmin` prunes them).
    corp=$(grep -o 'corp: [0-9]*' <<<"$last" | awk '{print $2}')
    files=$(find "$corpus" -maxdepth 1 -type f | wc -l)
    line=$(printf '%-12s %5ss  execs %-10s exec/s %-6s corpus %-5s (%s files)  cov %-5s ft %-6s crashes %s' \
        "$t" "$elapsed" "${execs:-?}" "${rate:-?}" "${corp:-?}" "$files" "${cov:-?}" "${ft:-?}" "$crashes")
    echo "$line"
    if [ "$crashes" -gt 0 ]; then
        grep -E '^(==[0-9]+==ERROR|thread .* panicked|SUMMARY|artifact_prefix|Test unit written)' "$log" | head -5 || true
    fi
    summary+=("$line")
done

echo
echo "fuzz summary (${secs}s per target, $(nproc) cores, $(rustc +nightly -V))"
printf '%s\n' "${summary[@]}"
exit "$failed"
