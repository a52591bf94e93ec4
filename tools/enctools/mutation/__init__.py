# SPDX-License-Identifier: Apache-2.0
"""Mutation coverage of the RTL (`make mutate`)."""
