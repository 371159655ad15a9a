#!/usr/bin/env bash
# Puts the browser editor's files where `remora serve` finds them: the page (web/index.html,
# style.css and its modules web/*.js) and the parts of three.js it imports, from web/node_modules
# (npm, installed here when missing: `npm ci` from web/package-lock.json). No CDN: the page works
# offline.
#
#   scripts/build_web.sh OUT_DIR
#
# kernel.wasm, the page's frames (web/wasm/kernel.cpp and the library's
# src/remora/multires/frame_replay.cpp for wasm32), is built with clang++ and wasm-ld (Debian's
# clang and lld); without them the page evaluates its frames in JavaScript, slower
# (docs/server.md), and this says so.
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

# The page's frames in WebAssembly: freestanding (no C library, and -fno-builtin keeps the
# compiler from calling a memset that none provides), the memory laid out by kernel.js.
wasm_tools() { command -v "${CLANGXX:-clang++}" >/dev/null && command -v wasm-ld >/dev/null; }
if wasm_tools; then
  # Shared memory (atomics, imported): the page's frames run on two threads (web/engine.js); the
  # stack pointer exported so that the worker's instance gets a stack of its own.
  "${CLANGXX:-clang++}" --target=wasm32 -std=c++20 -O3 -msimd128 -matomics -mbulk-memory \
    -mmutable-globals -nostdlib -fno-builtin -fno-exceptions -fno-rtti -Wall -Wextra -Werror \
    -I"$here/src" -Wl,--no-entry -Wl,--export=__heap_base -Wl,--export=__stack_pointer \
    -Wl,--shared-memory -Wl,--import-memory -Wl,--max-memory=4294967296 \
    -o "$out/kernel.wasm.tmp" "$web/wasm/kernel.cpp" "$here/src/remora/multires/frame_replay.cpp"
  mv "$out/kernel.wasm.tmp" "$out/kernel.wasm"
else
  rm -f "$out/kernel.wasm"
  echo "build_web: no clang++ or wasm-ld (Debian: clang, lld): the page's frames run in JavaScript"
fi
