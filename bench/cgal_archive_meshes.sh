#!/usr/bin/env bash
# Tries every mesh of CGAL's data archive (Debian's libcgal-demo: /usr/share/doc/libcgal-dev/
# data.tar.gz, 154 meshes) through `clumpkit fill` as it is, and, for those refused with a remedy
# named, with --repair-orientation or --repair-holes. Prints one line per mesh and the counts that
# docs/shape_error.md quotes (session 26).
#
#   bench/cgal_archive_meshes.sh [CLUMPKIT_BINARY]      (default build/apps/clumpkit/clumpkit)
set -uo pipefail
bin=$(realpath "${1:-build/apps/clumpkit/clumpkit}")
archive=/usr/share/doc/libcgal-dev/data.tar.gz
[ -x "$bin" ] || { echo "no clumpkit binary at $bin" >&2; exit 2; }
[ -f "$archive" ] || { echo "$archive missing: apt-get install libcgal-demo" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
tar xzf "$archive" -C "$work"
cd "$work"
fill() { timeout 300 "$bin" fill "$1" --method edt --spheres 2 --grid 32 --rays 20000 -o out.json "${@:2}" 2>&1 >/dev/null; }
ok=0 refused=0 orient=0 orient_ok=0 holes=0 holes_ok=0 holes_lid=0
while IFS= read -r f; do
  if err=$(fill "$f"); then
    ok=$((ok + 1)); echo "ok        $f"; continue
  fi
  refused=$((refused + 1))
  case "$err" in
    *--repair-orientation*)
      orient=$((orient + 1))
      if out=$(fill "$f" --repair-orientation); then
        orient_ok=$((orient_ok + 1)); echo "oriented  $f: $(grep -o 'repaired .*' <<<"$out" | head -1)"
      else echo "refused   $f (with --repair-orientation): ${out##*: }"; fi ;;
    *--repair-holes*)
      holes=$((holes + 1))
      if out=$(fill "$f" --repair-holes); then
        holes_ok=$((holes_ok + 1))
        grep -q 'partly made up' <<<"$out" && holes_lid=$((holes_lid + 1))
        echo "closed    $f: $(grep -o 'repaired .*' <<<"$out" | head -1)"
      else echo "refused   $f (with --repair-holes): $(head -1 <<<"$out" | sed 's/.*\.[a-z]*: //')"; fi ;;
    *) echo "refused   $f: $(head -1 <<<"$err" | sed 's/.*\.[a-z]*: //')" ;;
  esac
done < <(find data -name '*.off' -o -name '*.ply' -o -name '*.obj' -o -name '*.stl' | sort)
echo "== $((ok + refused)) meshes: $ok load as they are; $orient refused naming --repair-orientation ($orient_ok fill with it); $holes naming --repair-holes ($holes_ok fill with it, $holes_lid of them with lids over 5 % of the surface); $((refused - orient - holes)) refused with no remedy named"
