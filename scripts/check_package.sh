#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The encoder-model package stands on its own: install python/ with pip into a fresh venv (no
# project venv, no sys.path edits) and run its minimal cocotb example outside tb/
# (python/examples/minimal: a user's 4X counter driven by a modelled HEDS-5000). `make package-check`.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=build/package-check/venv
rm -rf build/package-check
mkdir -p build/package-check
command -v iverilog >/dev/null || { echo "package-check: needs Icarus Verilog (iverilog); run 'make venv' (installs it) or apt-get install iverilog" >&2; exit 1; }
echo "package-check: fresh venv in $venv"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check "./python[cocotb]" "pytest==9.2.0"
"$venv/bin/python" -c 'import sys, pkgutil, importlib, hedsmodel; [importlib.import_module("hedsmodel." + m.name) for m in pkgutil.iter_modules(hedsmodel.__path__)]; assert "cocotb" not in sys.modules, "the model core imported cocotb"'
cp -r python/examples/minimal build/package-check/example
cd build/package-check/example
"../venv/bin/python" -m pytest -q -p no:cacheprovider test_quad_counter.py
echo "package-check: OK (installed cocotbext-quadrature $("../venv/bin/python" -c 'import cocotbext.quadrature as q; print(q.__version__)'), example passed)"
