#!/usr/bin/env bash
# Build the manual with warnings as errors and check its local links, and that every doc page
# and every example is reachable from its index.  Exit status non-zero on any problem.
#   scripts/check_manual.sh [HTML_DIR]      (default build/doc-html)
# Needs Debian's python3-sphinx, python3-myst-parser, python3-sphinx-rtd-theme, python3-sphinx-argparse.
set -uo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$repo/build/doc-html}
py=/usr/bin/python3
status=0
rm -rf "$out"
# -W: warnings are errors; --keep-going: report all of them; -n: nitpicky cross-references.
if ! $py -m sphinx -W --keep-going -n -q -b html "$repo/doc" "$out"; then
  echo "check_manual: sphinx-build -W failed (warnings above)"
  status=1
fi
if ! $py "$repo/scripts/check_manual_links.py" "$out"; then
  status=1
fi
# Sphinx's own link check on the same sources, restricted to local links (conf.py ignores
# http(s): the machine has no internet access).
if ! $py -m sphinx -W --keep-going -q -b linkcheck "$repo/doc" "$out-linkcheck"; then
  echo "check_manual: sphinx linkcheck failed (see $out-linkcheck/output.txt)"
  status=1
fi
[[ $status -eq 0 ]] && echo "check_manual: manual in $out/index.html, no warnings, links OK"
exit $status
