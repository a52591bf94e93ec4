# SPDX-License-Identifier: Apache-2.0
"""Generators: everything derived from rtl/enc_qei.rdl and enc_ip.core (`make regs`)."""
