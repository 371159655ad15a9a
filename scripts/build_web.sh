#!/usr/bin/env bash
# Puts the browser editor's files where `remora serve` finds them: the page (web/index.html,
# style.css and its modules web/*.js) and the parts of three.js it imports, from web/node_modules
# (npm, installed here when missing: `npm ci` from web/package-lock.json). No CDN: the page works
# offline.
#
#   scripts/build_web.sh OUT_DIR
#
# The registry is reached over the network, which fails now and then, and npm by default waits 5
# minutes on a silent connection: here npm gives up on one after 60 s and retries each request
# itself, and the whole `npm ci` is tried up to REMORA_NPM_ATTEMPTS times (default 3) with a
# growing pause before the build gives up.
set -euo pipefail
out=${1:?usage: scripts/build_web.sh OUT_DIR}
here=$(cd "$(dirname "$0")/.." && pwd)
web="$here/web"
attempts=${REMORA_NPM_ATTEMPTS:-3}

installed() {
  [ -f "$web/node_modules/three/build/three.module.js" ] &&
    [ -f "$web/node_modules/playwright-core/package.json" ]
}

if ! installed; then
  if ! command -v npm >/dev/null; then
    echo "build_web: npm is missing; run scripts/bootstrap.sh --web (installs nodejs and npm)" >&2
    exit 1
  fi
  pause=10
  for ((i = 1; i <= attempts; i++)); do
    echo "build_web: installing three.js and playwright-core with npm ci (attempt $i of $attempts)"
    if (cd "$web" && npm ci --no-audit --no-fund --loglevel=error --fetch-retries=3 \
      --fetch-retry-mintimeout=2000 --fetch-retry-maxtimeout=20000 --fetch-timeout=60000); then
      break
    fi
    if [ "$i" -eq "$attempts" ]; then
      echo "build_web: npm ci failed $attempts times (its errors are above); most often the" \
        "npm registry is unreachable from this machine: check the network (or a proxy:" \
        "npm config get registry) and run make again" >&2
      exit 1
    fi
    echo "build_web: npm ci failed; trying again in $pause s" >&2
    sleep "$pause"
    pause=$((pause * 3))
  done
fi

mkdir -p "$out/three/build" "$out/three/examples/jsm/controls"
# The page: index.html, style.css and every ES module beside app.js (web/*.js).
cp "$web/index.html" "$web/style.css" "$web"/*.js "$out/"
cp "$web/node_modules/three/build/three.module.js" "$out/three/build/"
cp "$web/node_modules/three/examples/jsm/controls/OrbitControls.js" \
   "$web/node_modules/three/examples/jsm/controls/TransformControls.js" \
   "$out/three/examples/jsm/controls/"
cp "$web/node_modules/three/LICENSE" "$out/three/LICENSE"
