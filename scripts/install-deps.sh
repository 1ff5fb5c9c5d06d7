#!/usr/bin/env bash
# Installs every Debian package the ctid build and tests need, and fetches uPlot (MIT; inlined into the
# HTML reports) from the npm registry into third_party/uplot. Idempotent and quiet.
# Usage: scripts/install-deps.sh   (as root, or with sudo available)
set -euo pipefail

packages=(
  build-essential cmake pkg-config ccache
  libeigen3-dev nlohmann-json3-dev libcli11-dev libmatio-dev libsundials-dev libomp-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib python3-pandas python3-scipy
  python3-dask python3-distributed
  python3-pip python3-setuptools python3-wheel python3-venv
  clang libclang-rt-14-dev
  chromium
)
UPLOT_VERSION=1.6.32
uplot_dir="$(cd "$(dirname "$0")/.." && pwd)/third_party/uplot"

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
command -v npm >/dev/null 2>&1 || [ -f "$uplot_dir/uPlot.iife.min.js" ] || missing+=(npm)
if [ ${#missing[@]} -gt 0 ]; then
  $SUDO apt-get update -qq >/dev/null
  if ! $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/tmp/ctid-apt.log 2>&1; then
    cat /tmp/ctid-apt.log >&2
    exit 1
  fi
fi

if [ ! -f "$uplot_dir/uPlot.iife.min.js" ]; then
  tmp="$(mktemp -d)"
  (cd "$tmp" && npm pack --silent "uplot@$UPLOT_VERSION" >/dev/null 2>&1 && tar xzf "uplot-$UPLOT_VERSION.tgz")
  mkdir -p "$uplot_dir"
  cp "$tmp/package/dist/uPlot.iife.min.js" "$tmp/package/dist/uPlot.min.css" "$tmp/package/LICENSE" "$uplot_dir/"
  echo "$UPLOT_VERSION" > "$uplot_dir/VERSION"
  rm -rf "$tmp"
fi
