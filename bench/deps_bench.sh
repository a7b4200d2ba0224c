#!/bin/bash
# Install the Debian packages the benchmarks compare against (not needed by
# `make test`): LIGGGHTS for the DEM benchmark.
DEPS_PKGS="liggghts" exec bash "$(dirname "$0")/../scripts/deps.sh"
