#!/usr/bin/env bash
# ViewerUnderXvfb: shrefract-view in a virtual X server renders a bake for a few frames and saves
# a screenshot; the same view with --no-object is the reference. The glass must change at least
# 5% of the pixels. Exit 77 (ctest SKIP_RETURN_CODE) when xvfb-run is missing.
#   viewer_test.sh VIEWER PNG_DIFF BAKE ENV WORKDIR
set -euo pipefail
viewer=$1 png_diff=$2 bake=$3 env=$4 work=$5
if ! command -v xvfb-run >/dev/null; then
  echo "xvfb-run not found (apt-get install xvfb xauth): skipped"
  exit 77
fi
mkdir -p "$work"
# Under LeakSanitizer (scripts/test --sanitize): GLX and Xlib dlopen modules that the X client
# unloads at exit, so what they keep has no module left to name and tests/sanitizers/lsan.supp
# cannot suppress it; leak detection is off for this window-system test only (the code it draws
# with runs under LSan in every headless test).
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
rm -f "$work/shot.png" "$work/background.png"
run() { xvfb-run -a -s "-screen 0 800x600x24" "$viewer" "$bake" --env "$env" --size 640x480 "$@"; }
run --screenshot "$work/shot.png" --frames 3
run --screenshot "$work/background.png" --frames 3 --no-object
"$png_diff" "$work/shot.png" "$work/background.png" 0.05
# The method switch: Wyman's two-sided refraction draws the glass too, and differently from SH.
rm -f "$work/wyman.png"
run --screenshot "$work/wyman.png" --frames 3 --method wyman
"$png_diff" "$work/wyman.png" "$work/background.png" 0.05
"$png_diff" "$work/wyman.png" "$work/shot.png" 0.01
