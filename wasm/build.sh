#!/usr/bin/env bash
# Builds web/lib/gcs-skin.wasm from wasm/src with emscripten: a standalone module (no JS glue),
# 128-bit SIMD, growable memory. The exported functions are every gcs_* declared in the header.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
out="${1:-$root/web/lib/gcs-skin.wasm}"

if ! command -v emcc >/dev/null 2>&1; then
  echo "build:wasm: emcc not found. Install emscripten first: sudo apt-get install -y emscripten libglm-dev (Debian/Ubuntu)" >&2
  exit 1
fi
if [ ! -d /usr/include/glm ] && [ -z "${GLM_INCLUDE:-}" ]; then
  echo "build:wasm: GLM not found. Install it: sudo apt-get install -y libglm-dev (or set GLM_INCLUDE to the folder holding glm/)" >&2
  exit 1
fi
# Debian's emcc needs its own node modules (acorn) on NODE_PATH.
export NODE_PATH="${NODE_PATH:+$NODE_PATH:}/usr/share/nodejs"

# GLM through a folder that holds only a glm link: -I/usr/include would pull host libc headers.
build="$root/build/wasm"
mkdir -p "$build/include"
ln -sfn "${GLM_INCLUDE:-/usr/include}/glm" "$build/include/glm"

exports=$(grep -oE '\bgcs_[a-z0-9_]+\(' "$here/include/gcs_skin.h" | tr -d '(' | sort -u | sed 's/^/_/' | paste -sd, -)

emcc -O3 -DNDEBUG -msimd128 -std=c++17 -Wall -Wextra \
  -isystem "$build/include" \
  "$here"/src/*.cpp \
  -sSTANDALONE_WASM --no-entry \
  -sALLOW_MEMORY_GROWTH=1 -sINITIAL_MEMORY=16777216 -sMAXIMUM_MEMORY=4294967296 \
  -sEXPORTED_FUNCTIONS="$exports" \
  -o "$build/gcs-skin.wasm"
cp "$build/gcs-skin.wasm" "$out"
echo "build:wasm: wrote $out ($(wc -c < "$out") bytes)"
