#!/usr/bin/env bash
# Frame time with and without pipelining (DESIGN §1): `rivulet run` on the fountain, 120 frames, at 1 and
# 2 threads, pipelined (extraction of frame N+1 beside the render of frame N) and --no-pipeline (one after
# the other), without PNG output; then one pipelined run at 2 threads writing PNGs, for reference.
# Prints the medians of frame_ms, render_ms, extract_ms, max(render, extract) and render + extract.
#
#   perf/pipeline_figure.sh [BUILD_DIR]      (default: build)
set -euo pipefail

build=${1:-build}
bin="$build/bin/rivulet"
if [[ ! -x "$bin" ]]; then
    echo "pipeline_figure.sh: $bin not found (build the rivulet_cli target first)" >&2
    exit 1
fi
frames=${FRAMES:-120}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

echo "# $(date -u +%Y-%m-%dT%H:%MZ) | $(lscpu | sed -n 's/^Model name: *//p' | head -1) | nproc $(nproc)"
printf '| %-9s | %-2s | %-19s | %9s | %9s | %10s | %9s | %14s | %9s | %9s |\n' \
    mode T png frame_ms render_ms extract_ms "max(r,e)" "render+extract" "frame/max" "frame/sum"
echo "|-----------|----|---------------------|----------:|----------:|-----------:|----------:|---------------:|----------:|----------:|"

summarize() {  # mode threads png json
    python3 -c '
import json, sys
mode, t, png, path = sys.argv[1:5]
j = json.load(open(path))
f, r, e = j["frame_ms"], j["render_ms"], j["extract_ms"]
m = max(r, e)
print("| %-9s | %-2s | %-19s | %9.3f | %9.3f | %10.3f | %9.3f | %14.3f | %9.2f | %9.2f |"
      % (mode, t, png or "(none)", f, r, e, m, r + e, f / m if m > 0 else float("nan"), f / (r + e)))
' "$@"
}

run() {  # mode threads out
    local mode=$1 t=$2 out=$3 json="$tmp/$1-$2-${3:+png}.json"
    local extra=()
    [[ $mode == serial ]] && extra=(--no-pipeline)
    "$bin" run --scene fountain --frames "$frames" --threads "$t" --out "$out" --json "$json" "${extra[@]}" \
        >"$tmp/log" 2>&1 || { echo "rivulet run failed ($mode, T=$t):" >&2; cat "$tmp/log" >&2; exit 1; }
    summarize "$mode" "$t" "${out:+$out}" "$json"
}

for t in 1 2; do
    run pipelined "$t" ""
    run serial "$t" ""
done
rm -rf /tmp/rivulet-frames
mkdir -p /tmp/rivulet-frames
run pipelined 2 /tmp/rivulet-frames

echo
echo "Per-job medians of the frame graph (ms), same runs:"
python3 -c '
import json, sys
rows = [json.load(open(p)) | {"_name": p.rsplit("/", 1)[1][:-5]} for p in sys.argv[1:]]
names = list(rows[0]["stages"])
print("| run | " + " | ".join(names) + " |")
print("|---|" + "---:|" * len(names))
for r in rows:
    print("| %s | " % r["_name"] + " | ".join("%.3f" % r["stages"].get(n, float("nan")) for n in names) + " |")
' "$tmp"/pipelined-1-.json "$tmp"/serial-1-.json "$tmp"/pipelined-2-.json "$tmp"/serial-2-.json "$tmp"/pipelined-2-png.json
