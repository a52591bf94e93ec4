#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Lint every module in rtl/: Verilator --lint-only -Wall (with the reviewed waivers in
# rtl/lint_waivers.vlt) and an Icarus -Wall build. Any warning fails the run.
set -uo pipefail
cd "$(dirname "$0")/.."
export PATH="$PWD/scripts/bin:$PATH"

status=0
waivers=()
[ -f rtl/lint_waivers.vlt ] && waivers=(rtl/lint_waivers.vlt)

# lint_one <module> [-GNAME=value ...]
lint_one() {
  local top=$1; shift
  local out ivparams=()
  for g in "$@"; do ivparams+=("-P$top.${g#-G}"); done
  out=$(verilator --lint-only --quiet -Wall -Irtl "${waivers[@]}" --top-module "$top" "$@" rtl/*.v 2>&1)
  if [ $? -ne 0 ] || [ -n "$out" ]; then
    echo "verilator: $top $*"; echo "$out"; status=1
  fi
  out=$(iverilog -g2005 -Wall -o /dev/null -s "$top" "${ivparams[@]}" rtl/*.v 2>&1)
  if [ $? -ne 0 ] || [ -n "$out" ]; then
    echo "iverilog: $top $*"; echo "$out"; status=1
  fi
  checked=$((checked + 1))
}

checked=0
for file in rtl/*.v; do
  lint_one "$(basename "$file" .v)"
done
while read -r top params; do
  case "$top" in ''|'#'*) continue;; esac
  # shellcheck disable=SC2086
  lint_one "$top" $params
done < rtl/lint_params.txt
if [ $status -eq 0 ]; then
  echo "lint: $checked module/parameter sets clean (verilator -Wall, iverilog -Wall)"
else
  echo "lint: FAILED" >&2
fi
exit $status
