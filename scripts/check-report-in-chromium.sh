#!/usr/bin/env bash
# Opens an HTML report of schuler (e.g. the demo's) in headless Chromium and checks
# that it renders: Chromium loads it from disk with no network, its DOM holds every
# section of the table of contents and every plot, no console error is logged, every
# embedded SVG is well-formed XML with labelled axes, and a screenshot is taken.
#
#   scripts/check-report-in-chromium.sh [--install] REPORT.html [SCREENSHOT.png]
#
# --install installs Debian's chromium package first when it is missing (needs root
# and the Debian package registry).
set -euo pipefail

install=0
if [ "${1:-}" = "--install" ]; then
  install=1
  shift
fi
report=${1:?usage: $0 [--install] REPORT.html [SCREENSHOT.png]}
shot=${2:-}
[ -f "$report" ] || { echo "no report at $report" >&2; exit 1; }

if ! command -v chromium >/dev/null 2>&1; then
  if [ "$install" = 1 ]; then
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium >/dev/null
  else
    echo "chromium is not installed (apt-get install chromium, or pass --install)" >&2
    exit 1
  fi
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
url="file://$(realpath "$report")"
flags=(--headless --no-sandbox --disable-gpu --no-first-run --enable-logging=stderr --v=0)

chromium "${flags[@]}" --dump-dom "$url" >"$work/dom.html" 2>"$work/log.txt"
if grep -E "CONSOLE|Uncaught|Failed to load resource" "$work/log.txt"; then
  echo "$report: Chromium logged errors while loading it" >&2
  exit 1
fi

python3 - "$report" "$work/dom.html" <<'PY'
import re, sys, xml.etree.ElementTree as ET
source = open(sys.argv[1], encoding="utf-8").read()
dom = open(sys.argv[2], encoding="utf-8").read()
sections = re.findall(r'<section id="([^"]+)"', source)
missing = [s for s in sections if f'id="{s}"' not in dom]
svgs = re.findall(r"<svg.*?</svg>", source, flags=re.S)
rendered = len(re.findall(r"<svg", dom))
problems = []
if not sections:
    problems.append("no sections")
if missing:
    problems.append(f"sections missing from the rendered DOM: {missing}")
if rendered != len(svgs):
    problems.append(f"{len(svgs)} plots in the file but {rendered} rendered")
if re.search(r'(src|href)="(https?:)?//', source):
    problems.append("the report refers to an external resource")
for i, s in enumerate(svgs):
    try:
        ET.fromstring(s)
    except ET.ParseError as e:
        problems.append(f"plot {i + 1} is not well-formed SVG: {e}")
    texts = re.findall(r"<text[^>]*>([^<]*)</text>", s)
    if sum(1 for t in texts if re.search(r"\[[^\]]+\]", t)) < 2:
        problems.append(f"plot {i + 1} lacks axis labels with units")
if problems:
    sys.exit(f"{sys.argv[1]}: " + "; ".join(problems))
print(f"{sys.argv[1]}: {len(sections)} sections and {len(svgs)} plots render in Chromium")
PY

if [ -n "$shot" ]; then
  chromium "${flags[@]}" --window-size=1000,4000 --screenshot="$shot" "$url" 2>/dev/null
  [ -s "$shot" ] || { echo "no screenshot written" >&2; exit 1; }
  echo "screenshot: $shot"
fi
