#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job: the viewer on the Cornell box when a
# display exists, otherwise a headless run of vct-grid that writes every stage output to out/.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
if [ -n "${DISPLAY:-}" ] && "$root/build/voxlab" help view >/dev/null 2>&1; then
  exec "$root/build/voxlab" view --technique vct-grid --scene cornell-box "$@"
fi
out="$root/out/vct-grid-cornell-box"
echo "No display: running vct-grid headless; every stage output goes to $out"
exec "$root/build/voxlab" run --technique vct-grid --scene cornell-box --out "$out" "$@"
