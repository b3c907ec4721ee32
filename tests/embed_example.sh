#!/usr/bin/env bash
# The installed package as a consumer sees it (issue: Rivulet as a library): `cmake --install` into a
# fresh prefix, examples/embed configured against it with find_package(rivulet), built and run.
# Checks that only <rivulet/...> headers are installed, that none of the project's own flags reach the
# consumer's compile line, and that the installed Python module imports.
#   tests/embed_example.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(cd "$1" && pwd) src=$(cd "$2" && pwd)
work=$build/embed-check
rm -rf "$work"
mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"

headers=$(cd "$work/prefix/include" && find . -type f | sort)
if grep -v '^\./rivulet/[a-z_]*\.h$' <<< "$headers"; then
  echo "FAIL: installed headers outside include/rivulet (above)"; exit 1
fi
[ -f "$work/prefix/include/rivulet/rivulet.h" ] || { echo "FAIL: rivulet/rivulet.h not installed"; exit 1; }

cmake -S "$src/examples/embed" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON > "$work/configure.log"
if grep -E -e '-ffp-contract|-Wconversion|-Wshadow|include/rivulet[" ]|-I[^ ]*/(jobs|systems|runtime)\b' \
     "$work/build/compile_commands.json"; then
  echo "FAIL: the project's flags or internal include paths reach the consumer (above)"; exit 1
fi
cmake --build "$work/build" > "$work/build.log" || { cat "$work/build.log"; exit 1; }
"$work/build/embed" 2 2 | tee "$work/run.log"
[ "$(grep -c '^frame .*triangles, hash' "$work/run.log")" = 2 ] || { echo "FAIL: the example made no meshes"; exit 1; }
# The pipelined frames are the same meshes as the serial ones, in the same order.
if ! diff <(grep '^frame ' "$work/run.log") <(grep '^pipelined frame ' "$work/run.log" | sed 's/^pipelined //'); then
  echo "FAIL: the frame pipeline gave other meshes than the extractor (above)"; exit 1
fi
grep -q 'empty input: no particles to mesh' "$work/run.log" || { echo "FAIL: no rivulet::Error"; exit 1; }

if [ -n "${RIVULET_PYTHON:-}" ]; then
  site=$(find "$work/prefix" -name 'rivulet*.so' -printf '%h\n' | head -1)
  [ -n "$site" ] || { echo "FAIL: the Python module is not installed"; exit 1; }
  (cd "$work" && PYTHONPATH="$site" "$RIVULET_PYTHON" -c 'import rivulet, sys; assert rivulet.__file__.startswith(sys.argv[1]); print("installed module:", rivulet.__file__)' "$site")
fi
echo "embed example: OK"
