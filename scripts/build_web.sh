#!/usr/bin/env bash
# Puts the browser editor's files where `remora serve` finds them: the page (web/*.html, *.js,
# *.css) and the parts of three.js it imports, from web/node_modules (npm, installed here when
# missing: `npm ci` from web/package-lock.json). No CDN: the page works offline.
#
#   scripts/build_web.sh OUT_DIR
set -euo pipefail
out=${1:?usage: scripts/build_web.sh OUT_DIR}
here=$(cd "$(dirname "$0")/.." && pwd)
web="$here/web"

if [ ! -f "$web/node_modules/three/build/three.module.js" ]; then
  if ! command -v npm >/dev/null; then
    echo "build_web: npm is missing; run scripts/bootstrap.sh --web (installs nodejs and npm)" >&2
    exit 1
  fi
  echo "build_web: installing three.js and playwright-core with npm ci"
  (cd "$web" && npm ci --no-audit --no-fund --loglevel=error)
fi

mkdir -p "$out/three/build" "$out/three/examples/jsm/controls"
cp "$web/index.html" "$web/app.js" "$web/style.css" "$out/"
cp "$web/node_modules/three/build/three.module.js" "$out/three/build/"
cp "$web/node_modules/three/examples/jsm/controls/OrbitControls.js" \
   "$web/node_modules/three/examples/jsm/controls/TransformControls.js" \
   "$out/three/examples/jsm/controls/"
cp "$web/node_modules/three/LICENSE" "$out/three/LICENSE"
