#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Create .venv from the pinned requirements.txt and make sure the system tools the flow needs
# (Icarus Verilog, a C++ compiler and make for Verilator's model build) are present.
# Missing system tools are installed with apt-get when running as root; otherwise a one-line
# message names the package to install. Called by the Makefile; safe to run again.
# `bootstrap.sh --soc` (the soc targets, after the above) adds the LiteX SoC simulation: the RISC-V
# cross compiler and the libraries of LiteX's simulator from Debian, requirements-soc.txt into .venv.
# `bootstrap.sh --linux` (make linux-test) adds the kernel source and its build tools from Debian
# (linux-source-6.1, flex, bison, bc, perl, cpp) and requirements-linux.txt (dtschema) into .venv.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${1:-}" = "--linux" ]; then
  linux_pkgs=()
  compgen -G "/usr/src/linux-source-6.1*.tar.xz" >/dev/null || linux_pkgs+=(linux-source-6.1)
  command -v flex  >/dev/null 2>&1 || linux_pkgs+=(flex)
  command -v bison >/dev/null 2>&1 || linux_pkgs+=(bison)
  command -v bc    >/dev/null 2>&1 || linux_pkgs+=(bc)
  command -v perl  >/dev/null 2>&1 || linux_pkgs+=(perl)
  command -v cpp   >/dev/null 2>&1 || linux_pkgs+=(cpp)
  command -v xz    >/dev/null 2>&1 || linux_pkgs+=(xz-utils)
  [ -e /usr/include/linux/counter.h ] || linux_pkgs+=(linux-libc-dev)
  { [ -e /usr/lib/x86_64-linux-gnu/libc.a ] || [ -e /usr/lib/libc.a ]; } || linux_pkgs+=(libc6-dev)
  if [ ${#linux_pkgs[@]} -gt 0 ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
      echo "bootstrap: installing ${linux_pkgs[*]} with apt-get (make linux-test)"
      apt=(apt-get -o APT::Sandbox::User=root)
      if ! { "${apt[@]}" update -qq && DEBIAN_FRONTEND=noninteractive "${apt[@]}" install -y -qq "${linux_pkgs[@]}"; } >/tmp/bootstrap-apt-linux.log 2>&1; then
        echo "bootstrap: apt-get could not install ${linux_pkgs[*]} (see /tmp/bootstrap-apt-linux.log); install them and run again" >&2
        exit 1
      fi
    else
      echo "bootstrap: missing system packages for make linux-test: ${linux_pkgs[*]} (install them, e.g. 'sudo apt-get install ${linux_pkgs[*]}')" >&2
      exit 1
    fi
  fi
  echo "bootstrap: installing requirements-linux.txt into .venv"
  .venv/bin/python -m pip install -q --disable-pip-version-check -r requirements-linux.txt
  touch .venv/.linux-installed
  exit 0
fi

if [ "${1:-}" = "--soc" ]; then
  soc_pkgs=()
  command -v riscv64-unknown-elf-gcc >/dev/null 2>&1 || soc_pkgs+=(gcc-riscv64-unknown-elf)
  [ -e /usr/include/event2/event.h ] || soc_pkgs+=(libevent-dev)
  [ -e /usr/include/json-c/json.h ] || soc_pkgs+=(libjson-c-dev)
  [ -e /usr/include/zlib.h ] || soc_pkgs+=(zlib1g-dev)
  if [ ${#soc_pkgs[@]} -gt 0 ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
      echo "bootstrap: installing ${soc_pkgs[*]} with apt-get (LiteX SoC simulation)"
      apt=(apt-get -o APT::Sandbox::User=root)
      if ! { "${apt[@]}" update -qq && DEBIAN_FRONTEND=noninteractive "${apt[@]}" install -y -qq "${soc_pkgs[@]}"; } >/tmp/bootstrap-apt-soc.log 2>&1; then
        echo "bootstrap: apt-get could not install ${soc_pkgs[*]} (see /tmp/bootstrap-apt-soc.log); install them and run again" >&2
        exit 1
      fi
    else
      echo "bootstrap: missing system packages for the SoC simulation: ${soc_pkgs[*]} (install them, e.g. 'sudo apt-get install ${soc_pkgs[*]}')" >&2
      exit 1
    fi
  fi
  echo "bootstrap: installing requirements-soc.txt into .venv"
  .venv/bin/python -m pip install -q --disable-pip-version-check -r requirements-soc.txt
  touch .venv/.soc-installed
  exit 0
fi

need_pkgs=()
command -v iverilog >/dev/null 2>&1 || need_pkgs+=(iverilog)
command -v g++      >/dev/null 2>&1 || need_pkgs+=(g++)
command -v make     >/dev/null 2>&1 || need_pkgs+=(make)
python3 -c 'import venv, ensurepip' >/dev/null 2>&1 || need_pkgs+=(python3-venv)

if [ ${#need_pkgs[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "bootstrap: installing ${need_pkgs[*]} with apt-get"
    if ! { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need_pkgs[@]}"; } >/tmp/bootstrap-apt.log 2>&1; then
      echo "bootstrap: apt-get could not install ${need_pkgs[*]} (see /tmp/bootstrap-apt.log); install them and run again" >&2
      exit 1
    fi
  else
    echo "bootstrap: missing system packages: ${need_pkgs[*]} (install them, e.g. 'sudo apt-get install ${need_pkgs[*]}')" >&2
    exit 1
  fi
fi

# Optional: GTKWave and Xvfb, for `make waves` and the headless GTKWave check of the demo's save
# file (tb/demo/test_gtkwave.py, skipped without them). A failure here is a note, not an error.
opt_pkgs=()
command -v gtkwave  >/dev/null 2>&1 || opt_pkgs+=(gtkwave)
command -v xvfb-run >/dev/null 2>&1 || opt_pkgs+=(xvfb)
if [ ${#opt_pkgs[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "bootstrap: installing optional ${opt_pkgs[*]} with apt-get"
    # APT::Sandbox::User=root: in containers where /dev/null is not writable by apt's _apt user,
    # 'apt-get update' otherwise fails its signature check
    apt=(apt-get -o APT::Sandbox::User=root)
    if ! { "${apt[@]}" update -qq && DEBIAN_FRONTEND=noninteractive "${apt[@]}" install -y -qq "${opt_pkgs[@]}"; } >/tmp/bootstrap-apt-optional.log 2>&1; then
      echo "bootstrap: note: optional ${opt_pkgs[*]} not installed (see /tmp/bootstrap-apt-optional.log); GTKWave review and its test are skipped"
    fi
  else
    echo "bootstrap: note: optional packages for waveform review not installed: ${opt_pkgs[*]} (e.g. 'sudo apt-get install ${opt_pkgs[*]}')"
  fi
fi

py=$(command -v python3) || { echo "bootstrap: python3 (3.9 or newer) is required" >&2; exit 1; }
"$py" -c 'import sys; sys.exit(sys.version_info < (3, 9))' \
  || { echo "bootstrap: python3 is $("$py" --version 2>&1); 3.9 or newer is required" >&2; exit 1; }

if [ ! -x .venv/bin/python ]; then
  echo "bootstrap: creating .venv"
  "$py" -m venv .venv
fi
echo "bootstrap: installing requirements.txt into .venv"
.venv/bin/python -m pip install -q --disable-pip-version-check -r requirements.txt
touch .venv/.requirements-installed
