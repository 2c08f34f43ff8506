#!/bin/bash
# Peak memory and time of `qem simplify` on large hostile files (too slow or too big for
# the test suite), as recorded in FUZZING.md. Needs python3 and GNU time.
# Usage: fuzz/measure-hostile.sh [QEM_BINARY]   (default: target/dist/qem, built first)
set -eu
cd "$(dirname "$0")/.."
qem=${1:-target/dist/qem}
if [ $# -eq 0 ]; then cargo build --profile dist -p qem-cli -q; fi
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
python3 - "$dir" <<'PY'
import gzip, struct, sys
d = sys.argv[1]
tri = b"v 0 0 0\nv 1 0 0\nv 0 1 0\n"
def w(name, data):
    open(f"{d}/{name}", "wb").write(data)
w("absurd_count.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
  b"property float x\nproperty float y\nproperty float z\nelement face 1\n"
  b"property list uchar int vertex_indices\nend_header\n" + bytes(48))
w("absurd_count.stl", b" " * 80 + struct.pack("<I", 4000000000) + bytes(50))
w("comment_8MB_line.obj", b"# " + b"x" * (8 << 20) + b"\n" + tri + b"f 1 2 3\n")
w("number_8MB_line.obj", b"v 0 0 " + b"1" * (8 << 20) + b"\n" + tri + b"f 1 2 3\n")
w("w_64MB_line.obj", b"v 0 0 0 " + b"9" * (64 << 20) + b"\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
w("comment_64MB_line.off", b"OFF\n#" + b"x" * (64 << 20) + b"\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
w("coincident_1M.obj", tri + b"f 1 2 3\n" * 1000000)
w("coincident_5M.obj", tri + b"f 1 2 3\nf 3 2 1\n" * 2500000)
w("coincident_5M.off", b"OFF\n3 5000000 0\n0 0 0\n1 0 0\n0 1 0\n" + b"3 0 1 2\n3 2 1 0\n" * 2500000)
facet = struct.pack("<3f", 0, 0, 1) + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + b"\0\0"
w("coincident_2M.stl", b" " * 80 + struct.pack("<I", 2000000) + facet * 2000000)
with gzip.open(f"{d}/spaces_1000MB.obj.gz", "wb", 9) as f:
    f.write(tri + b"f 1 2 3\n")
    for _ in range(1000):
        f.write(b" " * (1 << 20))
PY
printf '| file | size | exit | time | peak RSS | message |\n|---|---|---|---|---|---|\n'
for f in "$dir"/*; do
  name=$(basename "$f")
  size=$(stat -c %s "$f")
  /usr/bin/time -o "$dir/.time" -f "%e %M" "$qem" simplify "$f" -o "$dir/.out.ply" 2> "$dir/.err" && rc=0 || rc=$?
  read -r secs kb < <(tail -n 1 "$dir/.time")
  msg=$(grep -v '^Command exited' "$dir/.err" | head -n 1 | sed "s|$dir/||")
  printf '| %s | %s B | %s | %s s | %s MB | %s |\n' "$name" "$size" "$rc" "$secs" "$((kb / 1024))" "${msg:-}"
  rm -f "$dir/.out.ply"
done
