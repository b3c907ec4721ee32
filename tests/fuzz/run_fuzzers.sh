#!/usr/bin/env bash
# Runs every fuzz target of a RIVULET_SANITIZE=fuzz build (docs/fuzzing.md).
#   tests/fuzz/run_fuzzers.sh BUILD_DIR SECONDS         each target for SECONDS (CI: 30)
#   tests/fuzz/run_fuzzers.sh BUILD_DIR --runs N        each target for N executions (long run: 10000000)
#   ... [--only fuzz_a,fuzz_b]                          a subset
#   ... [--parallel N]                                  N targets at a time (CI: one per core)
# Per target fuzz_<name>: first its checked-in regressions (tests/fuzz/regressions/<name>/, each input
# once), then fuzzing from the seed corpus (tests/fuzz/corpus/<name>/, read only) and
# BUILD_DIR/fuzz/fuzz_<name>/corpus, where new inputs go and stay for the next run; a failing input is
# saved in BUILD_DIR/fuzz/fuzz_<name>/.
# Fails (exit 1) if any target crashes, hangs, leaks or allocates over the caps below.
set -euo pipefail

usage() { sed -n '3,6p' "$0" >&2; exit 2; }
(($# >= 2)) || usage
build=$(cd "$1" && pwd)
shift
if [ "$1" = "--runs" ]; then
  (($# >= 2)) || usage
  budget=(-runs="$2") budget_text="$2 executions"
  shift 2
else
  budget=(-max_total_time="$1") budget_text="$1 s"
  shift
fi
only="" parallel=1
while (($# > 0)); do
  case "$1" in
    --only) only=",${2:?--only needs names}," && shift 2 ;;
    --parallel) parallel=${2:?--parallel needs a count} && shift 2 ;;
    *) usage ;;
  esac
done
[[ "$parallel" =~ ^[1-9][0-9]*$ ]] || usage

here=$(cd "$(dirname "$0")" && pwd)
# A single input running 5 s is a hang; 2 GiB resident or one allocation over 128 MiB is a reader
# sizing memory from a claimed count (inputs are a few KiB: a legit one allocates well under 1 MiB).
limits=(-timeout=5 -rss_limit_mb=2048 -malloc_limit_mb=128)
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
if ! command -v llvm-symbolizer >/dev/null && [ -x /usr/lib/llvm-14/bin/llvm-symbolizer ]; then
  export ASAN_SYMBOLIZER_PATH=/usr/lib/llvm-14/bin/llvm-symbolizer
fi
# The targets write each input to a scratch file under here; a crashing target cannot clean up itself.
shm=/dev/shm
[ -d "$shm" ] || shm=${TMPDIR:-/tmp}
RIVULET_FUZZ_SCRATCH=$(mktemp -d "$shm/rivulet-fuzz.XXXXXX")
export RIVULET_FUZZ_SCRATCH
trap 'rm -rf "$RIVULET_FUZZ_SCRATCH"' EXIT

# "NAME: value" from libFuzzer's final stats, "?" if absent.
final_stat() { sed -n "s/^stat::$1: *//p" "$2" | tail -1 | grep . || echo "?"; }
# "cov: N ft: N corp: N/SIZE" from the last status line.
status_field() { grep -E '^#[0-9]+' "$2" | grep -o "$1: [^ ]*" | tail -1 | cut -d' ' -f2 | grep . || echo "?"; }

# What failed, where, and on which input: the error line, the top of its stack, the saved input.
report() {
  {
    awk '/^Running: /{l=$0} END{if (l) print l}' "$1"
    grep -m2 -E 'ERROR: |fuzz finding|terminate called|runtime error|what\(\)' "$1" || true
    # the stack from the frame that failed, without the signal handler's and libFuzzer's own frames
    grep -E '^ +#[0-9]+ ' "$1" | grep -vE 'in (__sanitizer|__asan|__lsan|__ubsan|__interceptor|fuzzer::|__pthread_kill|raise|abort|__libc_start|_start)|libc\.so' |
      head -10 || true
    grep -E 'Test unit written' "$1" || true
  } | cut -c1-200 | sed 's/^/  /'
  echo "  full log: $1"
}

targets=()
for bin in "$build"/bin/fuzz_*; do
  [ -x "$bin" ] || continue
  name=$(basename "$bin")
  [ -z "$only" ] || [[ "$only" == *",$name,"* ]] || continue
  targets+=("$name")
done
((${#targets[@]} > 0)) || { echo "no fuzz targets in $build/bin (configure with -DRIVULET_SANITIZE=fuzz)" >&2; exit 2; }

# One target: its regressions, then fuzzing. Prints its summary (and what failed) to $work/summary and
# exits non-zero if anything failed, so that targets can run side by side and report in order.
fuzz_one() {
  local name=$1 bin=$build/bin/$1 short=${1#fuzz_} work=$build/fuzz/$1 rc=0 bad=0
  mkdir -p "$work/corpus"
  local dict=()
  [ -f "$here/dict/$short.dict" ] && dict=(-dict="$here/dict/$short.dict")
  {
    local regressions=()
    if [ -d "$here/regressions/$short" ]; then
      mapfile -t regressions < <(find "$here/regressions/$short" -type f ! -name '*.md' | sort)
    fi
    if ((${#regressions[@]} > 0)); then
      if ! "$bin" "${limits[@]}" "${regressions[@]}" >"$work/regressions.log" 2>&1; then
        echo "$name: FAILED on a checked-in regression input (tests/fuzz/regressions/$short):"
        report "$work/regressions.log"
        bad=1
      fi
    fi
    local start=$SECONDS
    "$bin" "${budget[@]}" "${limits[@]}" "${dict[@]}" -print_final_stats=1 -artifact_prefix="$work/" \
      "$work/corpus" "$here/corpus/$short" >"$work/fuzz.log" 2>&1 || rc=$?
    printf '%s: %-6s %s s, execs %s, exec/s %s, cov %s, ft %s, corpus %s, peak rss %s MB\n' "$name" \
      "$( ((rc == 0)) && echo ok || echo FAILED)" $((SECONDS - start)) \
      "$(final_stat number_of_executed_units "$work/fuzz.log")" "$(final_stat average_exec_per_sec "$work/fuzz.log")" \
      "$(status_field cov "$work/fuzz.log")" "$(status_field ft "$work/fuzz.log")" \
      "$(status_field corp "$work/fuzz.log")" "$(final_stat peak_rss_mb "$work/fuzz.log")"
    if ((rc != 0)); then
      report "$work/fuzz.log"
      bad=1
    fi
  } >"$work/summary"
  return $bad
}

echo "fuzzing ${#targets[@]} targets, $budget_text each, $parallel at a time"
declare -A pid_of
for name in "${targets[@]}"; do
  while (($(jobs -rp | wc -l) >= parallel)); do wait -n || true; done
  fuzz_one "$name" &
  pid_of[$name]=$!
done
failed=()
for name in "${targets[@]}"; do
  wait "${pid_of[$name]}" || failed+=("$name")
  cat "$build/fuzz/$name/summary"
done

if ((${#failed[@]} > 0)); then
  echo "fuzzing FAILED: ${failed[*]}"
  exit 1
fi
echo "fuzzing passed: ${#targets[@]} targets"
