# SPDX-License-Identifier: Apache-2.0
"""cocotb modules that the scripts run (make demo, make velocity, count_rate, sim_speed, sweep,
phase_adjust), and that tests run too; each reads its plan from and writes its results to files
named in ENC_-prefixed environment variables."""
