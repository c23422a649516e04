#!/bin/bash
# make demo (placeholder until the viewer lands): triangulate a bundled example.
set -eu
cd "$(dirname "$0")/.."
echo "demo: not built yet"
