#!/bin/sh
# make bench-denoise: see bench/denoise.py (the table in docs/hdr.md).
exec python3 "$(dirname "$0")/denoise.py" "$@"
