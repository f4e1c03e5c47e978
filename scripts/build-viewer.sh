#!/usr/bin/env bash
# Builds the web viewer into viewer/dist/index.html (one self-contained file; see docs/viewer.md).
# Installs its npm packages with `npm ci` (exact versions from viewer/package-lock.json, npm
# registry only) when node_modules is missing or older than the lock file, or always with --ci.
#   scripts/build-viewer.sh [--ci]
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$repo/viewer"
command -v npm >/dev/null || { echo "build-viewer: npm not found (install Node.js 20+, scripts/install-deps.sh)" >&2; exit 1; }
if [[ "${1:-}" == "--ci" || ! -f node_modules/.package-lock.json || package-lock.json -nt node_modules/.package-lock.json ]]; then
  npm ci --no-audit --no-fund --loglevel=error
fi
npx --no-install tsc --noEmit -p .
npx --no-install vite build --logLevel warn
echo "build-viewer: $repo/viewer/dist/index.html"
