#!/usr/bin/env bash
# The test command: installs what is missing (scripts/setup.sh), then runs every test, the
# editor's headless UI tests included (software wgpu adapter, no GPU or display needed).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
# winit and the Vulkan loader complain (harmlessly) when there is no runtime directory.
if [ -z "${XDG_RUNTIME_DIR:-}" ] || [ ! -d "$XDG_RUNTIME_DIR" ]; then
  XDG_RUNTIME_DIR=$(mktemp -d)
  chmod 700 "$XDG_RUNTIME_DIR"
  export XDG_RUNTIME_DIR
fi
# The web page's dependencies (wasm32) too: tests/architecture.rs reads `cargo tree --offline`
# for that target as well, and a build for this machine downloads only its own.
cargo fetch --locked --target wasm32-unknown-unknown
cargo test --all-targets "$@"

