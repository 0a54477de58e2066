#!/usr/bin/env bash
# Runs one browser test (web/test/NAME.js ARGS...) with node, after the shader build step; exits
# 77 (ctest: skipped) with the reason when node, the node modules of web/ or chromium are missing
# (scripts/setup installs all three). Usage: tests/web/run.sh NAME [ARGS...]
set -uo pipefail
web="$(cd "$(dirname "$0")/../../web" && pwd)"
name="$1"; shift
if ! command -v node >/dev/null; then echo "SKIP: no node (scripts/setup installs nodejs)"; exit 77; fi
if [ ! -d "$web/node_modules/playwright-core" ]; then
  echo "SKIP: no $web/node_modules (scripts/setup runs npm ci there)"; exit 77
fi
if [ "$name" != validator.test ] && [ "$name" != assets ] && [ ! -x "${SHREFRACT_CHROMIUM:-/usr/bin/chromium}" ]; then
  echo "SKIP: no chromium at ${SHREFRACT_CHROMIUM:-/usr/bin/chromium} (scripts/setup installs Debian's)"; exit 77
fi
node "$web/scripts/build-shaders.js" || exit 1
exec node "$web/test/$name.js" "$@"
