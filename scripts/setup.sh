#!/usr/bin/env bash
# Installs what fairmesh's tests need on a fresh Debian machine with Rust:
# - Debian packages: a software Vulkan/GL driver (the editor's tests render through wgpu on the
#   CPU), Xvfb and the X libraries winit loads (for screenshots of the real window), Node.js and
#   npm (the Khronos glTF validator checks exported files).
# - npm packages from package-lock.json (gltf-validator), into ./node_modules.
# It installs only what is missing, so running it again is cheap. apt-get runs directly as root
# and through sudo otherwise, so a user who is not root needs sudo rights for the first run.
# It does not install Rust (1.95 or newer, from rustup; see the README). It installs a C compiler
# (build-essential) when `cc` is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  mesa-vulkan-drivers libvulkan1 libegl1 libgl1-mesa-dri
  xvfb libxcursor1 libxi6 libxrandr2 libxkbcommon-x11-0 libxkbcommon0 libx11-xcb1
)
# Linking needs a C compiler, and a build script of the Wayland stack compiles C.
command -v cc >/dev/null 2>&1 || packages+=(build-essential)
# Node.js may come from elsewhere than Debian's package; only ask apt when it is absent.
command -v node >/dev/null 2>&1 || packages+=(nodejs)
command -v npm >/dev/null 2>&1 || packages+=(npm)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then
    if ! command -v sudo >/dev/null 2>&1; then
      echo "setup: these Debian packages are missing: ${missing[*]}" >&2
      echo "setup: install them as root (apt-get install ${missing[*]}), or install sudo" >&2
      exit 1
    fi
    echo "setup: not root, so apt-get runs through sudo (it may ask for your password)"
    sudo_cmd=(sudo)
  fi
  echo "setup: installing ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if [ -f package-lock.json ] && [ ! -d node_modules/gltf-validator ]; then
  echo "setup: npm ci (gltf-validator)"
  npm ci --no-audit --no-fund --loglevel=error
fi
