#!/usr/bin/env bash
# The test command: installs what is missing (scripts/setup.sh), then runs every test, the
# editor's headless UI tests included (software wgpu adapter, no GPU or display needed).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cargo test --all-targets "$@"
