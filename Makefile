# SPDX-License-Identifier: Apache-2.0
# HEDS-5000 encoder-interface IP: build, test and demo entry points. `make help` lists them.
# Every target bootstraps .venv from requirements.txt on first use (scripts/bootstrap.sh).

SHELL      := /bin/bash
VENV       := .venv
STAMP      := $(VENV)/.requirements-installed
SOC_STAMP  := $(VENV)/.soc-installed
LINUX_STAMP := $(VENV)/.linux-installed
PY         := $(VENV)/bin/python
SIM        ?= icarus
JOBS       ?= 2
WAVES      ?= 0
SEED       ?=
RPM        ?=
TEMP_C     ?=
CLK_HZ     ?=
BOARD      ?=

# scripts/bin holds our Verilator shim; it must come before any system verilator.
export PATH := $(CURDIR)/scripts/bin:$(CURDIR)/$(VENV)/bin:$(PATH)
export SIM SEED
export ENC_WAVES := $(WAVES)
# cocotb's runner reads WAVES itself and would switch Icarus to FST; we make VCD ourselves.
unexport WAVES

# demo and velocity pick the faster simulator themselves unless SIM is given on the command line
SIM_OR_AUTO = $(if $(filter command line,$(origin SIM)),$(SIM),auto)

.DEFAULT_GOAL := help

.PHONY: help venv demo waves test lint clean synth bitstream sweep formal mutate regs velocity package-check fusesoc soc-sim soc-bitstream linux-test

help: ## list the targets
	@echo "HEDS-5000 encoder-interface IP -- make targets:"
	@grep -hE '^[a-z][a-zA-Z_-]*:.*## ' $(MAKEFILE_LIST) | \
	  awk -F':.*## ' '{ printf "  make %-10s %s\n", $$1, $$2 }'
	@echo "Variables: SIM=icarus|verilator  WAVES=1 (VCD per test in sim/waves/)  SEED=n  JOBS=n"

$(STAMP): requirements.txt scripts/bootstrap.sh
	@bash scripts/bootstrap.sh

venv: $(STAMP) ## create .venv from requirements.txt (done automatically by every target)

$(SOC_STAMP): $(STAMP) requirements-soc.txt scripts/bootstrap.sh
	@bash scripts/bootstrap.sh --soc

$(LINUX_STAMP): $(STAMP) requirements-linux.txt scripts/bootstrap.sh
	@bash scripts/bootstrap.sh --linux

demo: $(STAMP) ## the main job: a modeled HEDS-5000 drives every circuit (RPM= TEMP_C= CLK_HZ= SEED=)
	@$(PY) scripts/demo.py --rpm "$(RPM)" --temp-c "$(TEMP_C)" --clk-hz "$(CLK_HZ)" --seed "$(SEED)" --sim $(SIM_OR_AUTO)

waves: $(STAMP) ## open the demo's sim/waves/demo.vcd in GTKWave with sim/demo.gtkw (or say how)
	@$(PY) scripts/demo.py --view

test: $(STAMP) ## run the cocotb regression (SIM=icarus default, or SIM=verilator; WAVES=1 for VCDs)
	@case "$(SIM)" in icarus|verilator) ;; *) echo "make test: SIM=$(SIM) is not supported; use SIM=icarus or SIM=verilator" >&2; exit 2;; esac
	@case "$(WAVES)" in 0|1) ;; *) echo "make test: WAVES=$(WAVES) must be 0 or 1" >&2; exit 2;; esac
	@case "$(SEED)" in ""|*[!0-9]*) [ -z "$(SEED)" ] || { echo "make test: SEED=$(SEED) must be a non-negative integer" >&2; exit 2; };; esac
	$(PY) -m pytest -n $(JOBS) tb boards python/tests

# make sweep runs on Verilator (much faster for long runs) unless SIM is given on the command line.
sweep: $(STAMP) ## dense model-driven count-limit sweep (FILTER_LEN 1..4 x phase error x frequency); doc/results/sweep_results.md + plot
	$(PY) scripts/sweep.py --sim $(if $(filter file,$(origin SIM)),verilator,$(SIM)) --jobs $(JOBS)

lint: $(STAMP) ## verilator --lint-only -Wall and iverilog -Wall on every module in rtl/
	@bash scripts/lint.sh

synth: $(STAMP) ## Yosys + nextpnr: every block (HX8K; enc_qei also ECP5) and the iCEBreaker top; tables in doc/results/synth_results.md and doc/results/synth_channels.md (QUICK=1: one seed, no table)
	$(PY) scripts/synth.py --jobs $(JOBS) $(if $(filter 1,$(QUICK)),--quick)

bitstream: $(STAMP) ## iCEBreaker bitstream: build/icebreaker/icebreaker_top.bin
	$(PY) scripts/synth.py --only icebreaker_top --bitstream

formal: $(STAMP) ## SymbiYosys proofs (k-induction) and covers of the counting circuits, one .sby per block
	$(PY) scripts/formal.py --jobs $(JOBS)

mutate: $(STAMP) ## mutation coverage: Yosys mutants of every RTL module against its tests (MUTATE_SEED=n)
	$(PY) scripts/mutate.py --jobs $(JOBS) $(if $(MUTATE_SEED),--seed $(MUTATE_SEED))

regs: $(STAMP) ## regenerate the enc_qei C header and register reference from rtl/enc_qei.rdl
	$(PY) scripts/gen_regs.py

velocity: $(STAMP) ## velocity-method accuracy benchmark on modelled HEDS-5000 units through enc_qei
	$(PY) scripts/velocity_bench.py --jobs $(JOBS) --sim $(SIM_OR_AUTO)

soc-sim: $(SOC_STAMP) ## LiteX SoC (VexRiscv + enc_qei, Verilator) running sw/soc firmware, checked against the motion; doc/results/soc_sim.md
	$(PY) scripts/soc_sim.py
	ENC_SOC_SIM=1 $(PY) -m pytest -q tb/soc

soc-bitstream: $(SOC_STAMP) ## the LiteX SoC with enc_qei on a board through Yosys/nextpnr (BOARD=icebreaker|icebreaker_engine|colorlight_i5|colorlight_i5_engine); doc/results/soc_bitstream.md
	@case "$(BOARD)" in icebreaker|icebreaker_engine|colorlight_i5|colorlight_i5_engine) ;; *) echo "make soc-bitstream: give BOARD=icebreaker, icebreaker_engine, colorlight_i5 or colorlight_i5_engine" >&2; exit 2;; esac
	$(PY) scripts/soc_bitstream.py --board $(BOARD)

linux-test: $(LINUX_STAMP) ## the enc-qei Linux counter driver in User-Mode Linux against the RTL (Verilator), checkpatch --strict, W=1, dt-validate
	$(PY) scripts/linux_test.py --jobs $(JOBS)

package-check: $(STAMP) ## pip-install python/ (cocotbext-quadrature) into a fresh venv and run its example outside tb/
	@bash scripts/check_package.sh

fusesoc: $(STAMP) ## run enc_ip.core's lint, sim and formal targets with FuseSoC itself (work in build/fusesoc)
	@rm -rf build/fusesoc && mkdir -p build/fusesoc
	@for t in lint sim formal; do echo "fusesoc: target $$t"; \
	  (cd build/fusesoc && fusesoc --cores-root $(CURDIR) run --target=$$t heds5000:enc:enc_ip > $$t.log 2>&1) \
	  || { echo "fusesoc: target $$t FAILED (build/fusesoc/$$t.log):"; tail -20 build/fusesoc/$$t.log; exit 1; }; done
	@echo "fusesoc: lint, sim and formal targets of enc_ip.core passed"

clean: ## remove simulation builds, waves and synthesis outputs (keeps .venv)
	rm -rf sim/build sim/waves sim/results build .pytest_cache tb/__pycache__ tb/*/__pycache__ scripts/__pycache__
	@echo "(kept .venv and the compiler cache .cache/; remove them by hand for a full reset)"
