#!/bin/sh
# The progress bar: on a terminal (a pseudo-terminal from util-linux `script`), `voxlab handout`
# redraws one line per step ("\r[###...] k/N  lesson: step ...") and ends on the full bar; with
# stderr not a terminal it prints no bar at all.
set -e
exe="$1"; root="$2"; out="$3"
rm -rf "$out"; mkdir -p "$out"
lesson="$root/tests/cli/handout/two-steps.md"
script -qec "'$exe' handout '$lesson' --size 64x64 --out '$out/tty'" /dev/null > "$out/tty.log"
grep -q "\[\.*\] 0/2  two-steps: step 1 voxelize/fragments" "$out/tty.log" || { cat "$out/tty.log"; echo "no bar at step 1"; exit 1; }
grep -q "\[#\{15\}\.\{15\}\] 1/2  two-steps: step 2 inject/radiance-injected" "$out/tty.log" || { cat "$out/tty.log"; echo "no half bar"; exit 1; }
grep -q "\[#\{30\}\] 2/2  two-steps: written two-steps.html" "$out/tty.log" || { cat "$out/tty.log"; echo "no full bar"; exit 1; }
"$exe" handout "$lesson" --size 64x64 --out "$out/pipe" > "$out/pipe.log" 2> "$out/pipe.err"
if grep -q '\[#' "$out/pipe.err" "$out/pipe.log"; then echo "a bar was drawn without a terminal"; exit 1; fi
grep -q "two-steps.html (2 steps)" "$out/pipe.log" || { cat "$out/pipe.log"; exit 1; }
echo "progress bar ok"
