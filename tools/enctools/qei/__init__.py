# SPDX-License-Identifier: Apache-2.0
"""The enc_qei test environment: the bus over either adapter (bus), the independent reference
model (model), the shared test environment and the one list of configurations (env), and the
stimulus (stimulus)."""
