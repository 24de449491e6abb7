#!/usr/bin/env bash
# Synthesis check of the SGM offload RTL with Yosys: generic `synth` (must finish without latches
# or unsupported constructs) and `synth_xilinx` for a 7-series part, reporting LUT / FF / BRAM /
# DSP counts. Usage: scripts/fpga-synth.sh [OUT_DIR] [LANES] [DMAX] [WMAX]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$here/build/fpga-synth}"
lanes="${2:-32}"
dmax="${3:-128}"
wmax="${4:-1024}"
mkdir -p "$out"
rtl="$here/fpga/rtl"
srcs="$rtl/sgm_top.v $rtl/sgm_core.v $rtl/sgm_census_unit.v $rtl/sgm_census5x5.v \
$rtl/sgm_cost_lanes.v $rtl/sgm_path_step.v $rtl/sgm_argmin.v $rtl/sgm_subpixel.v $rtl/sgm_lr_check.v"
params="-set LANES $lanes -set DMAX $dmax -set WMAX $wmax"

# Yosys' SAT-based passes (`share`, memory port sharing) run for hours on this design's wide muxes
# and gain little: both flows replace the stock coarse step by the same steps without them.
coarse="proc; flatten; opt_expr; opt_clean; check; opt -nodffe -nosdff; fsm; opt; wreduce; \
  peepopt; opt_clean; alumacc; opt; memory -nomap -nosat; opt_clean"

echo "== generic synth (LANES=$lanes DMAX=$dmax WMAX=$wmax)"
# Gates from the generic library; the generic library has no RAM, and turning the row buffers into
# flip-flops would only measure Yosys' patience, so memories stay \$mem cells (counted below).
yosys -q -l "$out/generic.log" -p "read_verilog $srcs; chparam $params sgm_top; \
  hierarchy -check -top sgm_top; $coarse; opt -fast -full; techmap; opt -fast; abc -fast; \
  opt -fast; check -assert; tee -o $out/generic_stat.txt stat" >/dev/null
if grep -qi "latch" "$out/generic_stat.txt" || grep -q "\$dlatch\|\$_DLATCH" "$out/generic_stat.txt"; then
  echo "latches found:"; grep -i latch "$out/generic_stat.txt"; exit 1
fi
grep -E "Number of cells|Number of wire bits|mem" "$out/generic_stat.txt" | head -6

echo "== synth_xilinx -family xc7"
yosys -q -l "$out/xilinx.log" -p "read_verilog $srcs; chparam $params sgm_top; \
  synth_xilinx -top sgm_top -family xc7 -flatten -run :map_dsp; \
  synth_xilinx -top sgm_top -family xc7 -flatten -run map_dsp:coarse; \
  techmap -map +/cmp2lut.v -map +/cmp2lcu.v -D LUT_WIDTH=6; alumacc; opt; \
  memory -nomap -nosat; opt_clean; \
  synth_xilinx -top sgm_top -family xc7 -flatten -run map_memory:; \
  tee -o $out/xilinx_stat.txt stat" >/dev/null
if grep -q "LDCE\|LDPE" "$out/xilinx_stat.txt"; then echo "latches found"; exit 1; fi
count() { awk -v pat="$1" '$1 ~ pat {s += $2} END {print s + 0}' "$out/xilinx_stat.txt"; }
luts=$(count '^LUT[1-6]$')
lutram=$(count '^RAM(32|64|128|256)')
srl=$(count '^SRL')
ffs=$(count '^FD[CPRSE]*$')
bram36=$(count '^RAMB36E1$')
bram18=$(count '^RAMB18E1$')
dsp=$(count '^DSP48E1$')
carry=$(count '^CARRY4$')
echo "LUT (logic)    $luts"
echo "LUTRAM cells   $lutram   SRL $srl"
echo "FF             $ffs"
echo "CARRY4         $carry"
echo "RAMB36E1       $bram36   RAMB18E1 $bram18   (BRAM36 equivalent $((bram36 + (bram18 + 1) / 2)))"
echo "DSP48E1        $dsp"
echo "no latches; reports in $out"
