#!/usr/bin/env bash
# Checks that two `qem` binaries write byte-identical meshes and identical reports (minus
# timings and paths) on a spread of corpus meshes and option sets. Used to show that a
# speed change leaves every output as it was.
#
# Usage: scripts/same_output.sh BEFORE_BINARY AFTER_BINARY [CORPUS_DIR]
# Exit status 0 when everything matches; prints one line per difference.
set -u
shopt -s nullglob
before=$1
after=$2
corpus=${3:-${QEM_CORPUS:-$(dirname "$0")/../../shared/corpus}}
work=$(mktemp -d /tmp/same_output.XXXXXX)
trap 'rm -rf "$work"' EXIT

meshes="npm_bunny c3d_suzanne igl_fertility stanford_dragon_vrip_res4 c3d_fandisk
ps_extruder_idler tm_fuze tm_angle_block oscad_issue945e drc_test_nm
cgaltest_nm_vertices_real cgaltest_many_umbrellas asp_3dsmax_export thingi10k_112932
pymeshfix_planar_mesh tm_wallhole"

# A lock file: every 7th vertex of the first few hundred.
seq 0 7 700 >"$work/lock.txt"

optsets=(
  ""
  "--ratio 0.01"
  "--ratio 0.2 --pair-threshold 0.01"
  "--ratio 0.1 --pair-threshold 0.02 --virtual-pairs between-parts"
  "--quadrics exact"
  "--ratio 0.05 --quadrics exact --pair-threshold 0.01"
  "--ratio 0.1 --preserve-topology"
  "--ratio 0.1 --lock-boundary"
  "--ratio 0.01 --max-error 0.002"
  "--ratio 0.1 --boundary-weight 0 --max-normal-angle 180"
  "--ratio 0.1 --min-quality 0.3 --weighting unweighted"
  "--ratio 0.1 --lock $work/lock.txt"
  "--lods 0.5,0.2,0.05"
  "--lods 0.5,0.1,0.01 --max-error 0.001"
)

strip() {
  python3 -c '
import json, sys
def clean(d):
    if isinstance(d, dict):
        return {k: clean(v) for k, v in d.items() if k not in ("timings_ms", "output", "input")}
    if isinstance(d, list):
        return [clean(x) for x in d]
    return d
print(json.dumps(clean(json.load(open(sys.argv[1]))), sort_keys=True, indent=1))
' "$1"
}

fail=0
runs=0
for m in $meshes; do
  input="$corpus/$m.obj"
  [ -f "$input" ] || { echo "missing $input"; fail=1; continue; }
  for i in "${!optsets[@]}"; do
    opts=${optsets[$i]}
    for side in before after; do
      bin=$before
      [ $side = after ] && bin=$after
      out="$work/$side.obj"
      case "$opts" in *--lods*) out="$work/$side-{lod}.obj" ;; esac
      # shellcheck disable=SC2086
      "$bin" simplify "$input" -o "$out" --report "$work/$side.json" -q $opts \
        >"$work/$side.log" 2>&1
      echo "exit $?" >>"$work/$side.log"
    done
    runs=$((runs + 1))
    if ! cmp -s "$work/before.log" "$work/after.log"; then
      echo "DIFF log: $m [$opts]"; fail=1
    fi
    for f in "$work"/before*.obj; do
      g=${f/before/after}
      if ! cmp -s "$f" "$g"; then echo "DIFF mesh $(basename "$f"): $m [$opts]"; fail=1; fi
    done
    if ! cmp -s <(strip "$work/before.json") <(strip "$work/after.json"); then
      echo "DIFF report: $m [$opts]"; fail=1
    fi
    rm -f "$work"/before*.obj "$work"/after*.obj
  done
done
# The full dragon (871k triangles) once, at the bench's ratio: the run being sped up.
for side in before after; do
  bin=$before
  [ $side = after ] && bin=$after
  "$bin" simplify "$corpus/stanford_dragon_vrip.obj" -o "$work/big-$side.obj" --ratio 0.1 \
    --report "$work/big-$side.json" -q || fail=1
done
runs=$((runs + 1))
cmp -s "$work/big-before.obj" "$work/big-after.obj" || { echo "DIFF mesh: dragon"; fail=1; }
cmp -s <(strip "$work/big-before.json") <(strip "$work/big-after.json") ||
  { echo "DIFF report: dragon"; fail=1; }
echo "$runs runs compared, $([ $fail = 0 ] && echo all identical || echo DIFFERENCES)"
exit $fail
