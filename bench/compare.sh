#!/bin/sh
# make bench-compare: see bench/compare.py.
exec python3 "$(dirname "$0")/compare.py" "$@"
