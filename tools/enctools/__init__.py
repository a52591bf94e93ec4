# SPDX-License-Identifier: Apache-2.0
"""enctools: the tooling of the HEDS-5000 encoder-interface IP.

One package for everything the repository runs besides the RTL: each module has one job.

  paths       where things are in the repository
  toolenv     the tools' environment (PATH with the Verilator shim first, compiler cache)
  core        enc_ip.core: source lists and parameter ranges (data, not prose)
  regmap      rtl/enc_qei.rdl compiled once, read by every Python consumer
  harness     build an HDL toplevel and run a cocotb module on it (hooks for mutation)
  tb          cocotb-side helpers: test start and seeds, the test decorator, reference models
  qei         the enc_qei test environment: bus, model, stimulus, configurations
  gen         generators: register block, C header, register reference, Verilog includes
  synth, formal, mutation, benches   the measurement flows behind `make synth|formal|mutate|...`
"""
