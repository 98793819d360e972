# SPDX-License-Identifier: MIT
# Sourced by the data-sheet checks: opens OUT/report.html in headless Chromium
# (a fresh profile, no network, no background services) and reads its DOM.
#   sheet_browser            the Chromium binary, or "" when none is installed
#   sheet_dump_dom OUT       writes OUT/dom.html
#   sheet_count OUT PATTERN  how often PATTERN stands in OUT/dom.html
#   sheet_decoded OUT        how many inlined PNGs the page decoded
sheet_browser() { command -v chromium || command -v chromium-browser || true; }

sheet_dump_dom() {
  "$(sheet_browser)" --headless --no-sandbox --disable-gpu --disable-background-networking \
    --disable-component-update --disable-sync --no-first-run --user-data-dir="$1/profile" \
    --virtual-time-budget=5000 --dump-dom "file://$1/report.html" >"$1/dom.html" \
    2>"$1/chromium.log"
}

sheet_count() { grep -o "$2" "$1/dom.html" | wc -l; }

sheet_decoded() { sed -n 's/.*data-images-decoded="\([0-9]*\)".*/\1/p' "$1/dom.html"; }
