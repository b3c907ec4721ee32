#!/usr/bin/env bash
# `mpirun -n 3 rivulet mesh` on loopback (docs/cluster.md): a sequence with a broken frame in the middle is
# meshed over three ranks; every good frame equals the single-process mesh byte for byte, the broken one
# is reported with its file and rank, the others are written, and the exit status says a frame failed.
# One frame split over 2 and 3 ranks (--decompose) is the single process's mesh as a set of triangles.
# Usage: mpi_batch.sh RIVULET MPIEXEC PYTHON (with NumPy)
set -euo pipefail
rivulet=$1
mpiexec=$2
python=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
# Root may run it in CI containers; more ranks than cores on a small machine.
mpirun=("$mpiexec" --allow-run-as-root --oversubscribe)

frames=7
"$rivulet" simulate --scene fountain --frames $frames --threads 1 --out "$work/in" > /dev/null
head -c 300 "$work/in/frame_00003.ply" > "$work/broken.ply"
mv "$work/broken.ply" "$work/in/frame_00003.ply"
mkdir "$work/single" "$work/ranks"
for i in 0 1 2 4 5 6; do
  "$rivulet" mesh "$work/in/frame_0000$i.ply" --method slices --threads 1 \
    --out "$work/single/mesh_0000$i.ply" > /dev/null
done

status=0
"${mpirun[@]}" -n 3 "$rivulet" mesh "$work/in/frame_{}.ply" --method slices --threads 1 \
  --out "$work/ranks/mesh_{}.ply" --json "$work/ranks.json" > "$work/stdout" 2> "$work/stderr" || status=$?
cat "$work/stdout"
[ "$status" -ne 0 ] || fail "a broken frame must make the exit status non-zero"
grep -q "frame_00003.ply (rank [0-2]): " "$work/stderr" || { cat "$work/stderr"; fail "no error for the broken frame"; }
grep -q "^meshed 6 of 7 frames over 3 ranks x 1 threads" "$work/stdout" || fail "no summary from rank 0"
grep -q "failed: .*frame_00003.ply (rank [0-2])" "$work/stdout" || fail "the summary does not name the broken frame"
[ ! -e "$work/ranks/mesh_00003.ply" ] || fail "a mesh was written for the broken frame"
for i in 0 1 2 4 5 6; do
  cmp "$work/single/mesh_0000$i.ply" "$work/ranks/mesh_0000$i.ply" || fail "frame $i differs from one process"
done
"$python" - "$work/ranks.json" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
frames = doc["frames"]
assert doc["ranks"] == 3 and doc["failed"] == 1, doc
assert [f["input"].endswith("frame_%05d.ply" % i) for i, f in enumerate(frames)] == [True] * 7, frames
assert all(0 <= f["rank"] < 3 for f in frames), frames
assert ("error" in frames[3]) and all("mesh_hash" in f for i, f in enumerate(frames) if i != 3), frames
assert sum(r["frames"] for r in doc["per_rank"]) == 7, doc["per_rank"]
PY

# One frame split over 2 and 3 ranks by slabs of blocks (--decompose): rank 0 writes one mesh, the single
# process's triangles as a set (positions and normals, bit for bit), watertight across the seams.
frame=(mesh "$work/in/frame_00006.ply" --method slices --radius 0.02 --block 12 --threads 1)
"$rivulet" "${frame[@]}" --out "$work/whole.ply" > /dev/null
for n in 2 3; do
  "${mpirun[@]}" -n $n "$rivulet" "${frame[@]}" --decompose --out "$work/pieces_$n.ply" > "$work/stdout"
  cat "$work/stdout"
  grep -q "in $n pieces along" "$work/stdout" || fail "no summary of the $n pieces"
done
"$python" - "$work/whole.ply" "$work/pieces_2.ply" "$work/pieces_3.ply" <<'PY'
import sys
import numpy as np

def read_ply(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().split("\n")
    nv = int(next(l for l in header if l.startswith("element vertex")).split()[2])
    nf = int(next(l for l in header if l.startswith("element face")).split()[2])
    vertices = np.frombuffer(data, dtype="<f4", count=nv * 6, offset=end).reshape(nv, 6)
    faces = np.frombuffer(data, dtype=np.dtype([("n", "u1"), ("i", "<u4", 3)]), count=nf, offset=end + nv * 24)
    assert (faces["n"] == 3).all()
    return vertices, faces["i"]

def triangles(vertices, faces):  # each triangle's three vertices as raw bits, rows sorted
    t = vertices.view("<u4")[faces].reshape(len(faces), 18)
    return t[np.lexsort(t.T[::-1])]

def open_edges(vertices, faces):  # edges of one triangle only (a crack), vertices merged by position
    _, ids = np.unique(np.ascontiguousarray(vertices[:, :3]).view("<u4"), axis=0, return_inverse=True)
    f = ids.reshape(-1)[faces]
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return int((counts == 1).sum())

whole = read_ply(sys.argv[1])
want = triangles(*whole)
assert len(want) > 10000, len(want)
assert open_edges(*whole) == 0
for path in sys.argv[2:]:
    got = read_ply(path)
    assert np.array_equal(triangles(*got), want), path + ": not the single process's triangles"
    assert open_edges(*got) == 0, path + ": open edges"
print("decompose: %d triangles, same set, watertight" % len(want))
PY

# A frame that cannot be split that many ways: every rank stops with the reason, none waits for the others.
status=0
timeout 60 "${mpirun[@]}" -n 3 "$rivulet" mesh "$work/in/frame_00006.ply" --method slices --radius 0.05 \
  --block 128 --decompose --out "$work/none.ply" > /dev/null 2> "$work/stderr" || status=$?
[ "$status" -ne 0 ] && [ "$status" -ne 124 ] || { cat "$work/stderr"; fail "an unsplittable frame must fail, not hang"; }
grep -q "fewer than the 3 pieces asked for" "$work/stderr" || { cat "$work/stderr"; fail "no reason given"; }
[ ! -e "$work/none.ply" ] || fail "a mesh was written"

# One file is not spread over ranks: a clear error, not three processes writing the same mesh.
status=0
"${mpirun[@]}" -n 2 "$rivulet" mesh "$work/in/frame_00000.ply" --method slices --out "$work/one.ply" \
  > /dev/null 2> "$work/stderr" || status=$?
[ "$status" -ne 0 ] || fail "one file under mpirun -n 2 must fail"
grep -q "give INPUT as a {} pattern, or split the one frame with --decompose" "$work/stderr" || { cat "$work/stderr"; fail "no explanation for one file"; }
# Other commands do not divide their work: refused rather than run as two copies writing the same files.
status=0
"${mpirun[@]}" -n 2 "$rivulet" simulate --scene fountain --frames 1 --out "$work/twice" \
  > /dev/null 2> "$work/stderr" || status=$?
[ "$status" -ne 0 ] || fail "simulate under mpirun -n 2 must fail"
grep -q "only \`rivulet mesh\` runs across MPI ranks" "$work/stderr" || { cat "$work/stderr"; fail "no reason given"; }
[ ! -e "$work/twice" ] || fail "simulate wrote files under mpirun -n 2"
echo "mpi batch: OK"
