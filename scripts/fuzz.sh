#!/usr/bin/env bash
# Runs the libFuzzer harnesses of a build folder (fuzz/CMakeLists.txt; docs/fuzzing.md).
#
#   scripts/fuzz.sh BUILD [HARNESS...]           each harness for FUZZ_SECONDS (default 180) on
#                                                its corpus BUILD/fuzz-corpus/HARNESS (kept and
#                                                grown from run to run, seeded from
#                                                BUILD/fuzz-seeds/HARNESS); what crashes, leaks,
#                                                hangs or runs out of memory is kept in
#                                                BUILD/fuzz-crashes/HARNESS/, the log in
#                                                BUILD/fuzz-logs/HARNESS.log; a table at the end;
#                                                with FUZZ_RUNS set, each stops after that many
#                                                executions instead (or at FUZZ_SECONDS)
#   scripts/fuzz.sh --smoke BUILD HARNESS        the seeds and a fixed number of mutations
#                                                (FUZZ_RUNS, default per harness) with a fixed
#                                                random seed, in a fresh corpus: the test of
#                                                make test
# Harnesses: obj off ply_ascii ply_binary ply_tristrips stl_ascii stl_binary edit_request server
# (all by default). Runs under `nice -n FUZZ_NICE` (default 19). Exit 1 when a harness failed.
set -euo pipefail

smoke=0
if [ "${1:-}" = "--smoke" ]; then
  smoke=1
  shift
fi
if [ $# -lt 1 ]; then
  echo "usage: scripts/fuzz.sh [--smoke] BUILD [HARNESS...]" >&2
  exit 2
fi
build=$(cd "$1" && pwd)
shift
harnesses=("$@")
if [ ${#harnesses[@]} -eq 0 ]; then
  harnesses=(obj off ply_ascii ply_binary ply_tristrips stl_ascii stl_binary edit_request server)
fi
here=$(cd "$(dirname "$0")/.." && pwd)
seconds=${FUZZ_SECONDS:-180}
nice_level=${FUZZ_NICE:-19}

# Per harness: dictionary, largest input, seconds before an input counts as a hang, the smoke
# run's mutations. Inputs stay small: the readers' bugs live in the parsing and in local repair
# decisions, which a few dozen faces reach, and a small input runs faster (binary records are
# dense: 2 kB is 40 STL triangles).
options() {
  case "$1" in
    obj | off) echo "$1 4096 10 20000" ;;
    ply_ascii) echo "ply 4096 10 20000" ;;
    ply_*) echo "ply 2048 10 20000" ;;
    stl_ascii) echo "stl 4096 10 20000" ;;
    stl_binary) echo "stl 2048 10 20000" ;;
    edit_request) echo "edit_request 4096 10 20000" ;;
    server) echo "server 8192 60 300" ;;
    *) return 1 ;;
  esac
}

failed=()
summary=()
for h in "${harnesses[@]}"; do
  if ! read -r dict max_len timeout runs < <(options "$h"); then
    echo "fuzz: unknown harness '$h'" >&2
    exit 2
  fi
  exe="$build/fuzz/remora_fuzz_$h"
  seeds="$build/fuzz-seeds/$h"
  if [ ! -x "$exe" ] || [ ! -d "$seeds" ]; then
    echo "fuzz: $exe or $seeds is missing: build the target remora_fuzzers first" >&2
    exit 2
  fi
  common=(-dict="$here/fuzz/dict/$dict.dict" -max_len="$max_len" -timeout="$timeout"
          -rss_limit_mb=2048 -malloc_limit_mb=1024 -print_final_stats=1)
  if [ "$smoke" -eq 1 ]; then
    work="$build/fuzz-smoke/$h"
    rm -rf "$work"
    mkdir -p "$work/corpus"
    log="$work/log"
    set +e
    nice -n "$nice_level" "$exe" "${common[@]}" -seed=1 -runs="${FUZZ_RUNS:-$runs}" \
      -artifact_prefix="$work/" "$work/corpus" "$seeds" >"$log" 2>&1
    status=$?
    set -e
  else
    corpus="$build/fuzz-corpus/$h"
    crashes="$build/fuzz-crashes/$h"
    log="$build/fuzz-logs/$h.log"
    mkdir -p "$corpus" "$crashes" "$build/fuzz-logs"
    echo "fuzz: $h for ${seconds} s${FUZZ_RUNS:+ or $FUZZ_RUNS executions} (log: $log)"
    set +e
    limits=(-max_total_time="$seconds")
    if [ -n "${FUZZ_RUNS:-}" ]; then limits+=(-runs="$FUZZ_RUNS"); fi
    nice -n "$nice_level" "$exe" "${common[@]}" "${limits[@]}" \
      -artifact_prefix="$crashes/" "$corpus" "$seeds" >"$log" 2>&1
    status=$?
    set -e
  fi
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  time=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  cov=$(grep -Eo 'cov: [0-9]+ ft: [0-9]+' "$log" | tail -1 || true)
  if [ "$status" -eq 0 ]; then
    result=ok
  else
    result="FAILED (exit $status)"
    failed+=("$h")
    if [ "$smoke" -eq 1 ]; then tail -n 60 "$log" >&2; fi
  fi
  summary+=("$(printf '%-14s %12s execs %8s/s  %-22s %s' "$h" "${execs:-?}" "${time:-?}" \
    "${cov:-cov: ?}" "$result")")
done

printf '%s\n' "${summary[@]}"
if [ ${#failed[@]} -gt 0 ]; then
  if [ "$smoke" -eq 0 ]; then
    echo "fuzz: failed: ${failed[*]}; the inputs are in $build/fuzz-crashes/<harness>/ and the" \
      "reports in $build/fuzz-logs/<harness>.log. Fix the bug, then add the input under" \
      "tests/fuzz/ (docs/fuzzing.md)." >&2
  fi
  exit 1
fi
