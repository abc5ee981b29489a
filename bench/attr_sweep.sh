#!/bin/sh
# The sweep behind AttributeWeights' defaults (docs/attributes.md): bench/attr_compare.py once per
# weight setting, qem measure only (200k samples), the peers' figures cached after the first run.
# usage: bench/attr_sweep.sh PEER_DIR OUT_DIR 'normal=0.01,uv=0.2' 'normal=0.03,uv=0.5' ...
set -e
peer=$1 out=$2
shift 2
here=$(dirname "$0")
for w in "$@"; do
  echo "## $w"
  nice -n 10 /usr/bin/python3 "$here/attr_compare.py" --peer "$peer" --out "$out" --no-check --samples 200000 \
    --tag "$w" --qem-arg=--attribute-weight --qem-arg="$w" ${ASSETS:+--assets "$ASSETS"} | tail -1
done
