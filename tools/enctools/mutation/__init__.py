# SPDX-License-Identifier: Apache-2.0
"""Mutation coverage of the RTL (`make mutate`, doc/mutation.md).

- ``modules``: the modules to mutate and the test paths that cover them.
- ``discover``: the tests, builds and parameter corners, found from those paths.
- ``generate``: the RTL snapshot and the Yosys side (mutants, single mutants, logic loops).
- ``plugin``: the pytest plugin whose harness hook runs a test's build with the mutants in it.
- ``loop``: the cocotb module that runs many mutants in one simulation.
- ``run``: the simulator processes of a corner, their watchdog, the verdicts.
- ``equivalence``: the equivalence checks of survivors.
- ``report``: results.json, the table, doc/results/mutation.md.
- ``cli``: the command line (scripts/mutate.py).
"""
