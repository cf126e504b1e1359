#!/usr/bin/env bash
# The editor as a web page: a folder of static files any static host serves (docs/web.md).
#
#   scripts/web.sh build [--dev] [OUT]   build the page into OUT (default target/web): index.html,
#                                        fairmesh_web.js and fairmesh_web_bg.wasm. The release
#                                        build (what is published) is the default; --dev builds
#                                        the quicker, larger debug build the browser test uses.
#   scripts/web.sh serve [PORT] [DIR]    serve DIR (default target/web) on 127.0.0.1:PORT (8000)
#   scripts/web.sh tools                 install what `build` needs and say what is missing
#
# Needs: rustup's wasm32-unknown-unknown target and wasm-bindgen-cli at exactly the version of
# wasm-bindgen in Cargo.lock (`tools` installs both). WASM_OPT=1 also runs wasm-opt on the
# release build (about 15% smaller); Debian 12's binaryen (version 108) breaks the module's
# reference-type table (the page fails to start), so it is off unless asked for, with a newer one.
set -euo pipefail
cd "$(dirname "$0")/.."

# The wasm-bindgen version the lock file pins: the command-line tool must be the same.
bindgen_version() {
  awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print; exit }' Cargo.lock
}

tools() {
  rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown ||
    rustup target add wasm32-unknown-unknown
  local want
  want="$(bindgen_version)"
  if [ "$(wasm-bindgen --version 2>/dev/null | awk '{print $2}')" != "$want" ]; then
    echo "web.sh: installing wasm-bindgen-cli $want (cargo install, a few minutes)"
    # The wasm-bindgen binary alone, without TLS (its test runner's downloads need it): quicker.
    cargo install --quiet wasm-bindgen-cli --version "$want" --no-default-features --bin wasm-bindgen
  fi
}

build() {
  local profile=release out=target/web
  if [ "${1:-}" = "--dev" ]; then
    profile=dev
    shift
  fi
  out="${1:-$out}"
  tools
  local flags=(--target wasm32-unknown-unknown -p fairmesh-web --lib)
  local target_dir="${CARGO_TARGET_DIR:-target}"
  local built
  if [ "$profile" = release ]; then
    cargo build --profile wasm-release "${flags[@]}"
    built=$target_dir/wasm32-unknown-unknown/wasm-release/fairmesh_web.wasm
  else
    cargo build "${flags[@]}"
    built=$target_dir/wasm32-unknown-unknown/debug/fairmesh_web.wasm
  fi
  mkdir -p "$out"
  rm -f "$out"/fairmesh_web*
  wasm-bindgen --target web --no-typescript --out-dir "$out" "$built"
  if [ "$profile" = release ] && [ "${WASM_OPT:-0}" = 1 ]; then
    # -O2 for speed; the features wasm-bindgen's output and rustc's default target use.
    wasm-opt -O2 --enable-bulk-memory --enable-nontrapping-float-to-int --enable-sign-ext \
      --enable-mutable-globals --enable-reference-types --enable-multivalue \
      "$out/fairmesh_web_bg.wasm" -o "$out/fairmesh_web_bg.wasm"
  fi
  cp web/index.html "$out/index.html"
  cp web/fairmesh_worker.js "$out/fairmesh_worker.js"
  # The bunny the page opens on start (the module does not carry it).
  cp assets/bunny00.obj "$out/bunny00.obj"
  local raw gz
  raw=$(stat -c %s "$out/fairmesh_web_bg.wasm")
  gz=$(gzip -9 -c "$out/fairmesh_web_bg.wasm" | wc -c)
  echo "web.sh: built $out ($profile): fairmesh_web_bg.wasm $raw bytes, $gz gzipped"
}

serve() {
  local port="${1:-8000}" dir="${2:-target/web}"
  [ -f "$dir/index.html" ] || { echo "web.sh: no $dir/index.html: run scripts/web.sh build first" >&2; exit 1; }
  echo "web.sh: serving $dir at http://127.0.0.1:$port/ (Ctrl+C stops)"
  exec python3 -m http.server --bind 127.0.0.1 --directory "$dir" "$port"
}

case "${1:-}" in
  build) shift; build "$@" ;;
  serve) shift; serve "$@" ;;
  tools) tools ;;
  *) sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
esac
