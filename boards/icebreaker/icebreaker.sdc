# SPDX-License-Identifier: Apache-2.0
# Timing constraint for the iCEBreaker board top (nextpnr-ice40 --sdc): the 12 MHz oscillator
# on pin 35 drives port clk. scripts/synth.py checks nextpnr applied it and that it is met.
create_clock -period 83.333 -name clk [get_ports clk]
