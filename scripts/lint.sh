#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Lint every module of the IP and of the board: Verilator --lint-only -Wall (with the reviewed
# waivers in rtl/lint_waivers.vlt) and an Icarus -Wall build, at the defaults and at every corner
# of every ranged parameter. The file lists and ranges come from enc_ip.core (enctools.core);
# boards/icebreaker/lint_params.txt adds the board's combined corners. The measurement model of
# `make synth`'s lane floor (tools/enctools/synth/floor/) is linted too, at the two schedules it
# is measured at. Any warning fails the run.
set -uo pipefail
cd "$(dirname "$0")/.."
export PATH="$PWD/scripts/bin:$PWD/.venv/bin:$PATH"
core() { .venv/bin/python -m enctools.core "$@"; }

mapfile -t ip_files < <(core files rtl | grep '\.v$')
mapfile -t incdirs < <(core incdirs)
inc=("${incdirs[@]/#/-I}")
mapfile -t board_files < <(core files board_icebreaker)
floor_files=(tools/enctools/synth/floor/enc_qei_floor_lane.v tools/enctools/synth/floor/enc_qei_floor_bank.v)
status=0
checked=0

# lint_one <module> [-GNAME=value ...]
lint_one() {
  local top=$1; shift
  local out ivparams=() files=("${ip_files[@]}")
  case " ${board_files[*]} " in *"/$top.v "*) files+=("${board_files[@]}");; esac
  case "$top" in enc_qei_floor_*) files+=("${floor_files[@]}");; esac
  for g in "$@"; do ivparams+=("-P$top.${g#-G}"); done
  out=$(verilator --lint-only --quiet -Wall "${inc[@]}" rtl/lint_waivers.vlt --top-module "$top" "$@" "${files[@]}" 2>&1)
  if [ $? -ne 0 ] || [ -n "$out" ]; then
    echo "verilator: $top $*"; echo "$out"; status=1
  fi
  out=$(iverilog -g2005 -Wall "${inc[@]}" -o /dev/null -s "$top" "${ivparams[@]}" "${files[@]}" 2>&1)
  if [ $? -ne 0 ] || [ -n "$out" ]; then
    echo "iverilog: $top $*"; echo "$out"; status=1
  fi
  checked=$((checked + 1))
}

for file in "${ip_files[@]}" "${board_files[@]}"; do
  lint_one "$(basename "$file" .v)"
done
while read -r top params; do
  # shellcheck disable=SC2086
  lint_one "$top" $params
done < <(core corners; grep -v '^\s*\(#\|$\)' boards/icebreaker/lint_params.txt)
lint_one enc_qei_floor_lane
lint_one enc_qei_floor_bank -GP=16
lint_one enc_qei_floor_bank -GN=16 -GP=384
if [ $status -eq 0 ]; then
  echo "lint: $checked module/parameter sets clean (verilator -Wall, iverilog -Wall)"
else
  echo "lint: FAILED" >&2
fi
exit $status
