#!/usr/bin/env bash
# Screenshot of the HTML report as a user sees it, with headless Chromium (Debian's package).
#
#   scripts/screenshot-report.sh [REPORT.html] [OUT.png]
#
# Defaults: out/index.html (written by `cargo run --release`) and docs/report.png, both
# relative to the repository root. Installs nothing; if Chromium is missing it says how to
# install it. The PNG is reduced to a palette with pngquant or ImageMagick when one of them is
# there (keeps docs/report.png small), else left as Chromium wrote it.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
page=${1:-$root/out/index.html}
shot=${2:-$root/docs/report.png}
browser=$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)
if [ -z "$browser" ]; then
    echo "chromium not found: install it with  sudo apt-get install chromium" >&2
    exit 1
fi
if [ ! -f "$page" ]; then
    echo "$page not found: run  cargo run --release  first (it writes out/index.html)" >&2
    exit 1
fi
page=$(cd "$(dirname "$page")" && pwd)/$(basename "$page")
mkdir -p "$(dirname "$shot")"
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
# --no-sandbox: Chromium refuses to run as root with its sandbox (containers, CI).
"$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
    --user-data-dir="$profile" --window-size=1400,2000 \
    --screenshot="$shot" "file://$page" 2>/dev/null
if command -v pngquant >/dev/null; then
    pngquant --force --skip-if-larger --output "$shot" 256 -- "$shot" || true
elif command -v convert >/dev/null && convert -version 2>/dev/null | grep -q ImageMagick; then
    convert "$shot" -colors 256 PNG8:"$shot"
fi
echo "screenshot: $shot ($(du -k "$shot" | cut -f1) KB)"
