#!/bin/sh
# Command-line contract of cairn stereo, stereo-eval and bench stereo: good runs produce their
# files and JSON, every bad input exits non-zero with a message on stderr.
# usage: stereo_cli_test.sh CAIRN DATA_DIR WORK_DIR   (exit 77 = skipped, data missing)
set -u
C=$1
D=$2/stereo/middlebury2003-cones
M=$2/stereo/middlebury2014q-motorcycle
T=$3
[ -f "$D/im2.png" ] || { echo "missing $D"; exit 77; }
[ -f "$M/im0.png" ] || { echo "missing $M"; exit 77; }
mkdir -p "$T"

expect_fail() {
  if "$@" >"$T/out" 2>"$T/err"; then echo "FAIL: succeeded: $*"; exit 1; fi
  if ! grep -q . "$T/err"; then echo "FAIL: no message for: $*"; exit 1; fi
  echo "ok (fails with: $(head -c 160 "$T/err" | head -n 1)): $*"
}
expect_ok() {
  if ! "$@" >"$T/out" 2>"$T/err"; then echo "FAIL: $*"; cat "$T/err"; exit 1; fi
  echo "ok: $*"
}

# Good runs.
expect_ok "$C" stereo "$D/im2.png" "$D/im6.png" --max-disparity 64 --out "$T/cones.pfm" --png "$T/cones.png"
[ -s "$T/cones.pfm" ] && [ -s "$T/cones.png" ] || { echo "FAIL: no output files"; exit 1; }
expect_ok "$C" stereo-eval --est "$T/cones.pfm" --gt "$D/disp2.png" --gt-scale 4 --metric bad1
grep -q '"bad_nonocc"' "$T/out" && grep -q '"density"' "$T/out" && grep -q '"scored_all"' "$T/out" || { echo "FAIL: JSON"; cat "$T/out"; exit 1; }
expect_ok "$C" stereo-eval --est "$T/cones.pfm" --gt "$D/disp2.png" --gt-scale 4 --metric bad3
grep -q '"metric": "bad3"' "$T/out" && grep -q '"bad_nonocc_interpolated"' "$T/out" || { echo "FAIL: JSON"; cat "$T/out"; exit 1; }
expect_ok "$C" stereo "$M/im0.png" "$M/im1.png" --max-disparity 96 --min-disparity 0 --paths 8 --out "$T/moto.pfm"
expect_ok "$C" stereo-eval --est "$T/moto.pfm" --gt "$M/disp0GT.pfm" --mask "$M/mask0nocc.png" --metric bad0.5
expect_ok "$C" bench stereo --left "$M/im0.png" --right "$M/im1.png" --size 160x96 --max-disparity 32 --iterations 1
grep -q 'opencv-sgbm-3way' "$T/out" && grep -q 'opencv-hh4' "$T/out" || { echo "FAIL: bench output"; exit 1; }
# The cosimulated FPGA gives the same file as the CPU kernel in the FPGA mode (raster4 paths).
expect_ok "$C" stereo "$D/im2.png" "$D/im6.png" --max-disparity 64 --backend fpga-sim --out "$T/cones-fpga.pfm"
grep -q 'device cycles' "$T/out" || { echo "FAIL: no fpga-sim cycles"; exit 1; }
expect_ok "$C" stereo "$D/im2.png" "$D/im6.png" --max-disparity 64 --paths raster4 --out "$T/cones-raster.pfm"
cmp "$T/cones-fpga.pfm" "$T/cones-raster.pfm" || { echo "FAIL: fpga-sim differs from raster4"; exit 1; }
expect_ok "$C" bench fpga --left "$M/im0.png" --right "$M/im1.png" --size 96x32 --max-disparity 64
grep -q 'bit-exact vs golden (scalar raster_paths): yes' "$T/out" || { echo "FAIL: bench fpga"; cat "$T/out"; exit 1; }

# Bad input.
expect_fail "$C" stereo "$D/im2.png" "$D/im6.png" --max-disparity 64 --backend fpga-sim --census 9x7 --out "$T/x.pfm"
expect_fail "$C" bench fpga --size 96x32 --max-disparity 48
expect_fail "$C" stereo "$D/im2.png" "$D/missing.png" --max-disparity 64 --out "$T/x.pfm"
expect_fail "$C" stereo "$D/im2.png" "$M/im1.png" --max-disparity 64 --out "$T/x.pfm"
expect_fail "$C" stereo "$D/im2.png" "$D/im6.png" --max-disparity 50 --out "$T/x.pfm"
expect_fail "$C" stereo "$D/im2.png" "$D/im6.png" --max-disparity 64 --min-disparity 64 --out "$T/x.pfm"
expect_fail "$C" stereo "$D/im2.png" "$D/im6.png" --max-disparity abc --out "$T/x.pfm"
expect_fail "$C" stereo "$D/im2.png" "$D/im6.png" --max-disparity 64 --paths 6 --out "$T/x.pfm"
expect_fail "$C" stereo "$D/im2.png" "$D/im6.png" --max-disparity 64
expect_fail "$C" stereo "$D/im2.png" "$D/im6.png" --max-disparity 64 --out "$T/no/such/dir/x.pfm"
expect_fail "$C" stereo "$D/im2.png" "$D/im6.png" --max-disparity 64 --calib "$T/no-dataset" --out "$T/x.pfm"
expect_fail "$C" stereo "$D/im2.png" "$D/im6.png" --max-disparity 64 --bogus 1 --out "$T/x.pfm"
expect_fail "$C" stereo-eval --est "$T/missing.pfm" --gt "$D/disp2.png"
expect_fail "$C" stereo-eval --est "$T/cones.pfm" --gt "$D/missing.png"
expect_fail "$C" stereo-eval --est "$T/cones.pfm" --gt "$M/disp0GT.pfm"
expect_fail "$C" stereo-eval --est "$T/cones.pfm" --gt "$D/disp2.png" --metric bad5
expect_fail "$C" stereo-eval --est "$D/im2.png" --gt "$D/disp2.png"
expect_fail "$C" bench stereo --left "$M/im0.png" --right "$M/im1.png" --size 10x10
expect_fail "$C" bench stereo --left "$M/missing.png" --right "$M/im1.png"
echo "all stereo CLI checks passed"
