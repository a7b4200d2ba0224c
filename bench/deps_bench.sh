#!/bin/bash
# Install the Debian packages the benchmarks compare against (not needed by
# `make test`): LIGGGHTS for the DEM benchmark, YADE (its FlowEngine) for the
# pore-network benchmark.
DEPS_PKGS="liggghts yade" exec bash "$(dirname "$0")/../scripts/deps.sh"
