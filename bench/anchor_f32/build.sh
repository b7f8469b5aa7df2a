#!/usr/bin/env bash
# Builds the float C anchor (ctrnn_simd_f32.c) into OUT (default: this folder) as
# libctrnn_simd_f32.so, with the flags of ../shared/anchors/c/build.sh for its double anchor.
# ANCHOR_MARCH=x86-64-v3 builds the AVX2 anchor on an AVX-512 machine (default: native).
#
#   bash bench/anchor_f32/build.sh [OUT]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=${1:-$here}
lib="$out/libctrnn_simd_f32.so"
gcc -O3 -march="${ANCHOR_MARCH:-native}" -mprefer-vector-width=512 -ffast-math -fopenmp -fPIC -shared \
  -DB="${SIMD_BLOCK:-32}" -o "$lib" "$here/ctrnn_simd_f32.c" -lmvec -lm
# It must call libmvec's float vector exponential: 16 lanes on AVX-512, 8 on AVX2.
disassembly=$(objdump -d "$lib")  # (not piped into grep -q, whose early exit fails the pipe)
grep -qE '_ZGV(eN16|dN8)v_expf' <<< "$disassembly" || { echo "$lib: no vector expf" >&2; exit 1; }
echo "built: $lib"
