#!/usr/bin/env bash
# Regenerates BENCHMARKS.md from the per-component pages in docs/benchmarks/ (each page holds its
# tables and the exact command that produced every figure).
set -euo pipefail
cd "$(dirname "$0")/.."
pages=(proximity sphere_tree bake sampling cfm contact_tree sdfbake narrowphase degradation world engines python)
{
  echo "# Benchmarks"
  echo
  echo "Every figure below comes with the command that produced it. The machines are shared and"
  echo "noisy (2 cores, often 5-15 other processes compiling): single-thread figures are CPU time"
  echo "medians; peers are measured **in the same run** and compared by ratio. Regenerate this page"
  echo "with \`scripts/gather-benchmarks.sh\` after editing a page under \`docs/benchmarks/\`."
  echo
  for p in "${pages[@]}"; do
    f="docs/benchmarks/$p.md"
    [ -f "$f" ] || continue
    echo "---"
    echo
    # Demote headings one level so each page becomes a section (not `#` lines inside fenced
    # code blocks: shell comments); relative image links are rewritten to point into
    # docs/benchmarks/ from the repository root.
    # A page's "## History" (dated earlier runs) stays on the page: BENCHMARKS.md is the current summary.
    awk '/^```/ { fenced = !fenced } !fenced && /^## History/ { exit } !fenced && /^#/ { $0 = "#" $0 } { print }' "$f" |
      sed -e 's/](\([A-Za-z0-9_.-]*\.\(png\|svg\)\))/](docs\/benchmarks\/\1)/g'
    echo
  done
} > BENCHMARKS.md.tmp
mv BENCHMARKS.md.tmp BENCHMARKS.md
