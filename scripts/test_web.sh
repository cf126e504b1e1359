#!/usr/bin/env bash
# The editor's web page tested in a real browser (CI runs it as a step of its own; docs/web.md):
# installs what it needs (Debian's chromium, the wasm32 target, wasm-bindgen-cli, npm's
# playwright-core), builds the page (the quicker debug build: scripts/web.sh build --dev), serves
# it on 127.0.0.1 with the test files beside it, and runs web/tests/browser.mjs three times: with
# the renderer the browser picks (WebGL2: headless with --disable-gpu it has no WebGPU adapter),
# with WebGL2 alone, and with the browser's software WebGPU (the page must draw through WebGPU). Then it checks the
# downloads against the command-line tool: the exported OBJ's positions equal `fairmesh multires`
# at the same level within 1e-5 of the bounding box's diagonal, with the same .mtl and texture,
# and the broken file's error is the one `fairmesh info` gives. Screenshots, downloads and the
# figures (time to the first picture) are left in target/web-test-out/.
set -euo pipefail
cd "$(dirname "$0")/.."

missing=()
command -v chromium >/dev/null 2>&1 || missing+=(chromium)
if [ ${#missing[@]} -gt 0 ]; then
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  echo "test_web: installing ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
if [ ! -d node_modules/playwright-core ]; then
  npm ci --no-audit --no-fund --loglevel=error
fi

site=target/web-test
results=target/web-test-out
scripts/web.sh build --dev "$site"
rm -rf "$results" "$site/data"
mkdir -p "$results" "$site/data"
cp tests/data/roundtrip/{scene.gltf,scene.bin,checker.png,textured.obj,textured.mtl,textured.png} "$site/data/"
# A face that names a vertex the file does not have.
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n' > "$site/data/broken.obj"

cargo build --quiet --bin fairmesh
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
python3 -m http.server --bind 127.0.0.1 --directory "$site" "$port" >"$results/server.log" 2>&1 &
server=$!
trap 'kill "$server" 2>/dev/null || true' EXIT
for _ in $(seq 50); do
  python3 -c "import urllib.request; urllib.request.urlopen('http://127.0.0.1:$port/')" 2>/dev/null && break
  sleep 0.1
done

status=0
for backend in "" webgl2 webgpu; do
  FAIRMESH_WEB_URL="http://127.0.0.1:$port/" FAIRMESH_WEB_OUT="$results" \
    FAIRMESH_WEB_BACKEND="$backend" FAIRMESH_WEB_DATA="$site/data" \
    node web/tests/browser.mjs || status=1
done

# The downloads against the command-line tool.
python3 web/tests/check_downloads.py "$results" "$site/data" target/debug/fairmesh || status=1
exit $status
