#!/usr/bin/env bash
# Browser test of the web viewer (docs/viewer.md): builds the viewer, runs the bunny-on-box demo
# with glTF export, serves it with `clod view --port 0`, and drives the page in Debian's headless
# Chromium (viewer/e2e/viewer.e2e.mjs). Exits non-zero on any failure; the server is always stopped.
#   scripts/test-viewer.sh [PATH/TO/clod]      (default: $CLOD_BIN, else build/bin/clod)
# Environment: CLOD_VIEWER_SCREENSHOT=FILE.png keeps the screenshot there (default: in $TMPDIR);
#              CLOD_VIEWER_FIXTURE=1 uses viewer/e2e/make-fixture.mjs instead of `clod simulate`;
#              CHROMIUM_PATH overrides /usr/bin/chromium.
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
clod="${1:-${CLOD_BIN:-$repo/build/bin/clod}}"
[[ -x "$clod" ]] || { echo "test-viewer: no clod binary at '$clod' (build target clod_cli, or pass its path)" >&2; exit 2; }
clod="$(cd "$(dirname "$clod")" && pwd)/$(basename "$clod")"
command -v node >/dev/null || { echo "test-viewer: node not found" >&2; exit 1; }
[[ -x "${CHROMIUM_PATH:-/usr/bin/chromium}" ]] || { echo "test-viewer: no Chromium at ${CHROMIUM_PATH:-/usr/bin/chromium}" >&2; exit 1; }

tmp="$(mktemp -d "${TMPDIR:-/tmp}/clod-viewer-test.XXXXXX")"
server_pid=""
cleanup() {
  if [[ -n "$server_pid" ]]; then
    kill "$server_pid" 2>/dev/null || true
    wait "$server_pid" 2>/dev/null || true
  fi
  rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

timeout 300 "$repo/scripts/build-viewer.sh"

if [[ "${CLOD_VIEWER_FIXTURE:-0}" == 1 ]]; then
  (cd "$repo/viewer" && node e2e/make-fixture.mjs "$tmp/out")
else
  timeout 300 "$clod" simulate "$repo/scenes/bunny_on_box.json" -o "$tmp/out" --gltf
fi

# --quit-after: a safety net should this script be killed before its trap runs.
"$clod" view "$tmp/out" --port 0 --quit-after 900 >"$tmp/server.log" 2>&1 &
server_pid=$!
url=""
for _ in $(seq 1 300); do
  url="$(grep -o 'http://[^ ]*/' "$tmp/server.log" | head -n 1 || true)"
  [[ -n "$url" ]] && break
  kill -0 "$server_pid" 2>/dev/null || { cat "$tmp/server.log" >&2; echo "test-viewer: clod view exited" >&2; exit 1; }
  sleep 0.1
done
[[ -n "$url" ]] || { cat "$tmp/server.log" >&2; echo "test-viewer: clod view printed no URL within 30 s" >&2; exit 1; }
echo "test-viewer: serving at $url"

shot="${CLOD_VIEWER_SCREENSHOT:-${TMPDIR:-/tmp}/clod-viewer-e2e.png}"
cd "$repo/viewer"
timeout 180 node e2e/viewer.e2e.mjs --url "$url" --out "$tmp/out" --screenshot "$shot" --page-file dist/index.html
