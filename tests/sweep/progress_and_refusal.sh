#!/bin/sh
# The progress bar of `voxlab sweep`: on a terminal (a pseudo-terminal from util-linux `script`)
# one line redrawn per run ("[###...] k/N  NAME=VALUE") ending on the full bar; with stderr not a
# terminal no bar at all. And bad input runs nothing: a value out of range exits 2 and leaves no
# output folder behind.
set -e
exe="$1"; out="$2"
rm -rf "$out"; mkdir -p "$out"
sweep="sweep --technique vct-grid --param cone.aperture=30,60 --set voxel.resolution=32 --size 64x64"
script -qec "'$exe' $sweep --out '$out/tty'" /dev/null > "$out/tty.log"
grep -q "sweep \[\.\{30\}\] 0/2  cone.aperture=30" "$out/tty.log" || { cat "$out/tty.log"; echo "no bar at run 1"; exit 1; }
grep -q "sweep \[#\{15\}\.\{15\}\] 1/2  cone.aperture=60" "$out/tty.log" || { cat "$out/tty.log"; echo "no half bar"; exit 1; }
grep -q "sweep \[#\{30\}\] 2/2  done" "$out/tty.log" || { cat "$out/tty.log"; echo "no full bar"; exit 1; }
"$exe" $sweep --out "$out/pipe" > "$out/pipe.log" 2> "$out/pipe.err"
if grep -q '\[#' "$out/pipe.err" "$out/pipe.log"; then echo "a bar was drawn without a terminal"; exit 1; fi
grep -q "2 runs in" "$out/pipe.log" || { cat "$out/pipe.log"; exit 1; }
rc=0; "$exe" sweep --technique vct-grid --param cone.aperture=30,60,500 --out "$out/refused" 2> "$out/refused.err" || rc=$?
[ "$rc" = 2 ] || { echo "a value out of range exited $rc, want 2"; exit 1; }
[ ! -e "$out/refused" ] || { echo "a refused sweep wrote $out/refused"; exit 1; }
echo "progress bar and refusal ok"
