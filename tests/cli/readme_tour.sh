#!/usr/bin/env bash
# Usage: readme_tour.sh CLUMPKIT SOURCE_DIR
# Keeps the README's "Quick tour" true: runs its commands as a newcomer would, from a folder laid
# out like the repository's root (build/apps/clumpkit/clumpkit, examples/), one after the other,
# and fails on the first that does not exit 0 or that leaves no output where the tour says it
# writes one. The rig, synth, compare and diagnose lines (minutes of simulation) are left to
# their own tests (rigs, calibrate.loop_through_rigs.*); every other line runs as written.
set -euo pipefail
ck_bin="$(realpath "$1")"
src="$(realpath "$2")"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT

# The tour: the first ```sh block after "## Quick tour".
awk '/^## Quick tour/ { in_section = 1 }
     in_section && /^```sh/ { in_block = 1; next }
     in_block && /^```/ { exit }
     in_block' "$src/README.md" > "$dir/tour.sh"
[ -s "$dir/tour.sh" ] || { echo "FAIL: no quick-tour block found in README.md"; exit 1; }

cd "$dir"
mkdir -p build/apps/clumpkit
ln -s "$ck_bin" build/apps/clumpkit/clumpkit
cp -r "$src/examples" examples

ran=0
skipped=0
while IFS= read -r line; do
  case "$line" in
    '' | '#'*) continue ;;
    'ck='*) eval "$line"; continue ;;
    '$ck rig '* | '$ck synth '* | '$ck compare '* | '$ck diagnose '*) skipped=$((skipped + 1)); continue ;;
  esac
  echo "== $line"
  if ! eval "$line" > out.log 2>&1; then
    tail -n 20 out.log
    echo "FAIL: a README tour command failed: $line"
    exit 1
  fi
  # Every -o FILE|FOLDER/ and --out FOLDER/ the line names must exist afterwards.
  for target in $(grep -oE '(-o|--out|--plot) [^ ]+' <<< "$line" | awk '{print $2}'); do
    [ -e "$target" ] || { echo "FAIL: '$line' left no $target"; exit 1; }
  done
  ran=$((ran + 1))
done < "$dir/tour.sh"

# What the tour's outputs must hold, beyond existing.
grep -q '"spheres"' a12.json || { echo "FAIL: a12.json holds no spheres"; exit 1; }
ls liggghts_a12/*.liggghts > /dev/null 2>&1 || { echo "FAIL: no LIGGGHTS template in liggghts_a12/"; exit 1; }
last=$(tail -n 1 pour/series.csv)
clumps=$(cut -d, -f3 <<< "$last")
[ "$clumps" = 300 ] || { echo "FAIL: the example pour ended with $clumps clumps, not 300"; exit 1; }
in_cup=$(cut -d, -f5 <<< "$last")
awk -v m="$in_cup" 'BEGIN { exit !(m > 0.04) }' ||
  { echo "FAIL: the example pour put $in_cup kg in the cup (300 pills B are ~0.053 kg)"; exit 1; }
[ "$ran" -ge 10 ] || { echo "FAIL: only $ran tour commands ran"; exit 1; }
echo "ok: $ran README tour commands ran ($skipped simulation lines left to their own tests)"
