# hydrostatic.gp: the chart of sph2d bench accuracy's hydrostatic case, what accuracy costs in
# time: error against wall seconds per simulated second, log-log, one series per solver (filled
# marks: the solver's default CFL-type number, open: twice it), each point labelled with its
# particle count, the Pareto front drawn. Its data: hydrostatic.dat beside it.
#   gnuplot hydrostatic.gp                 draws hydrostatic.svg and hydrostatic.png beside this file
#   gnuplot -c hydrostatic.gp A.svg B.png   draws A.svg and B.png
me = "hydrostatic.gp"
n = strlen(ARG0) - strlen(me)
dir = (n > 0 && ARG0[n+1:] eq me) ? ARG0[1:n] : ""
data = dir . "hydrostatic.dat"
svg = ARGC >= 1 ? ARG1 : dir . "hydrostatic.svg"
png = ARGC >= 2 ? ARG2 : dir . "hydrostatic.png"

set encoding utf8
set logscale xy
set xrange [0.0070592:15.8761]
set yrange [0.000301042:0.499704]
set xtics ("0.01" 0.01, "0.1" 0.1, "1" 1, "10" 10)
set ytics ("0.0005" 0.0005, "0.001" 0.001, "0.002" 0.002, "0.005" 0.005, "0.01" 0.01, "0.02" 0.02, "0.05" 0.05, "0.1" 0.1, "0.2" 0.2)
set lmargin at screen 0.115; set rmargin at screen 0.8
set bmargin at screen 0.095; set tmargin at screen 0.88
set xlabel "cost: wall seconds per simulated second  (s/s)"
set ylabel "error: worst deviation of the pressure profile from ρ_0 g (H - y)\n(share of ρ_0 g H)"
set title "hydrostatic: error against cost\n{/*0.8 lower left is better; the grey line joins the Pareto front: the runs no other run beats in both}"
set grid xtics ytics lc rgb "#dddddd" lw 1
set key outside right top vertical Left reverse noenhanced spacing 1.15 font ",10"
set label 1 "not drawn (no figure):\npbf 12.8k ×2" at screen 0.82, screen 0.4 left front font ",9" noenhanced

set terminal svg size 960,600 fixed enhanced font "DejaVu Sans,12" background rgb "white"
set output svg
plot \
  data index 5 using 1:2 with lines lw 8 lc rgb "#a0909090" title "Pareto front", \
  data index 5 using 1:2 with points pt 6 ps 2.6 lw 1.5 lc rgb "#606060" notitle, \
  data index 0 using 1:($4 == 1 ? $2 : NaN) with points pt 7 ps 1.4 lc rgb "#E69F00" title "muller2003", \
  data index 0 using 1:($4 != 1 ? $2 : NaN) with points pt 6 ps 1.4 lw 2 lc rgb "#E69F00" notitle, \
  data index 0 using 6:7:3 with labels left font ",9" tc rgb "#E69F00" notitle, \
  data index 1 using 1:($4 == 1 ? $2 : NaN) with points pt 5 ps 1.4 lc rgb "#0072B2" title "wcsph", \
  data index 1 using 1:($4 != 1 ? $2 : NaN) with points pt 4 ps 1.4 lw 2 lc rgb "#0072B2" notitle, \
  data index 1 using 6:7:3 with labels left font ",9" tc rgb "#0072B2" notitle, \
  data index 2 using 1:($4 == 1 ? $2 : NaN) with points pt 9 ps 1.4 lc rgb "#009E73" title "dfsph", \
  data index 2 using 1:($4 != 1 ? $2 : NaN) with points pt 8 ps 1.4 lw 2 lc rgb "#009E73" notitle, \
  data index 2 using 6:7:3 with labels left font ",9" tc rgb "#009E73" notitle, \
  data index 3 using 1:($4 == 1 ? $2 : NaN) with points pt 13 ps 1.4 lc rgb "#CC79A7" title "pbf", \
  data index 3 using 1:($4 != 1 ? $2 : NaN) with points pt 12 ps 1.4 lw 2 lc rgb "#CC79A7" notitle, \
  data index 3 using 6:7:3 with labels left font ",9" tc rgb "#CC79A7" notitle, \
  data index 4 using 1:($4 == 1 ? $2 : NaN) with points pt 15 ps 1.4 lc rgb "#D55E00" title "game", \
  data index 4 using 1:($4 != 1 ? $2 : NaN) with points pt 14 ps 1.4 lw 2 lc rgb "#D55E00" notitle, \
  data index 4 using 6:7:3 with labels left font ",9" tc rgb "#D55E00" notitle, \
  keyentry with points pt 7 ps 1.4 lc rgb "#404040" title "CFL ×1", \
  keyentry with points pt 6 ps 1.4 lw 2 lc rgb "#404040" title "CFL ×2"
unset output

if (strstrt(" " . GPVAL_TERMINALS . " ", " pngcairo ") > 0) {
  set terminal pngcairo size 960,600 enhanced font "DejaVu Sans,11" background rgb "white"
} else {
  set terminal png size 960,600 enhanced font "DejaVuSans,10" background rgb "white"
}
set output png
replot
unset output
