# SPDX-License-Identifier: Apache-2.0
"""``make linux-test``: the enc-qei Linux counter driver (sw/linux/) in a User-Mode Linux kernel,
its register accesses served by a Verilator model of enc_qei_wb over a Unix socket.

- ``kernel``: Debian's linux-source tree, the driver and the UML bridge laid into it, the kernel
  configuration (cached by its key), the build, W=1 and checkpatch --strict;
- ``binding``: the devicetree binding checked with dtschema (dt-doc-validate, dt-validate);
- ``model``: the Verilator model server, one build per enc_qei parameter set;
- ``boot``: the root file system (the test init and the module), the devicetree, one UML boot
  against one model, its console parsed into results;
- ``cli``: the command line of scripts/linux_test.py.
"""
