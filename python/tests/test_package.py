# SPDX-License-Identifier: Apache-2.0
"""The model core of the cocotbext-quadrature package (hedsmodel) imports no cocotb, and the
installed package is the one the tests and scripts use (no sys.path edits). The fresh-venv install
and the example outside tb/ are `make package-check` (scripts/check_package.sh, run by CI)."""

import importlib
import pkgutil
import subprocess
import sys
from pathlib import Path

import hedsmodel

TOP = Path(__file__).resolve().parents[2]


def test_model_core_imports_no_cocotb():
    names = ["hedsmodel." + m.name for m in pkgutil.iter_modules(hedsmodel.__path__)]
    code = ("import importlib, sys\n"
            f"for n in {names!r}: importlib.import_module(n)\n"
            "bad = sorted(m for m in sys.modules if m == 'cocotb' or m.startswith('cocotb.'))\n"
            "print(','.join(bad))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                         cwd="/")
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "", f"the model core imported {out.stdout.strip()}"
    assert len(names) >= 7, names


def test_package_is_installed_from_python_dir():
    for name in ("hedsmodel", "cocotbext.quadrature"):
        mod = importlib.import_module(name)
        assert Path(mod.__file__).resolve().is_relative_to(TOP / "python" / "src"), mod.__file__


def test_scripts_do_not_edit_sys_path_for_the_model():
    for script in ("error_budget.py", "monte_carlo.py"):
        text = (TOP / "scripts" / script).read_text()
        assert "sys.path" not in text, f"scripts/{script} edits sys.path"
